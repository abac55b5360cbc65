// SPDX-License-Identifier: MIT
// A pole's range bounds from a forward model of its return (sl_rfit.h).
#include "shadowlean/sl_rfit.h"

#include <limits.h>
#include <string.h>

#include "shadowlean/sl_fx.h"

#define LN2_Q16 45426   // ln 2, Q16
#define MIN_W_Q8 32     // b >= a + 1/8 bin
#define MAX_STEP_Q8 1024 // at most 4 bins per iteration
#define TOL_Q8 4        // converged below 1/64 bin
#define NORM_BITS 20    // the window's peak is normalised to ~2^20
#define JT_MAX ((int64_t)1 << 20) // scaled Jacobian and residual clamp (Q14: 64)
#define LEVEL_MAX ((uint64_t)1 << 36) // the level's bound (the window's powers are ~2^20)
#define FADE_P_Q16 66 // a fade deeper than speckle makes over the window: probability 1e-3

typedef struct pieces {
    int32_t x[SL_RFIT_PIECES + 1]; // breakpoints, bins Q8 (window coordinates)
    int32_t coef[SL_RFIT_PIECES];  // mass / (width x CT), scaled so m_q24 = coef x dC >> 24
    uint32_t inv_w[SL_RFIT_PIECES]; // 2^32 / width (width in bins Q8)
    int32_t dxa[SL_RFIT_PIECES + 1]; // d x_j / d a, Q16
    int32_t dxb[SL_RFIT_PIECES + 1]; // d x_j / d b, Q16
    uint8_t np;
} pieces_t;

typedef struct normal {
    int64_t n[3][3]; // Fisher information (unweighted), Q28
    int64_t g[3];    // score, Q28
} normal_t;

typedef struct ldl {
    int64_t d[3];   // Q28
    int64_t l10, l20, l21; // Q16
    bool ok;
} ldl_t;

#define RING SL_RESP_TAPS

// The fit's work memory (sl_rfit_ws_t): the model's pieces at the point being evaluated,
// the normal equations and their factor, and the covariance pass's ring of the last RING
// samples' projected Jacobians. Each user rebuilds what it reads; none is live across
// another's use.
typedef struct work {
    pieces_t p;
    normal_t ne;
    ldl_t f;
    int16_t ra[RING], rb[RING]; // projected Jacobians, Q10
} work_t;

_Static_assert(sizeof(work_t) <= sizeof(sl_rfit_ws_t), "sl_rfit_ws_t: SL_RFIT_WS_BYTES too small");

typedef struct ctx {
    work_t *w;
    const sl_response_t *r;
    const sl_rfit_in_t *in;
    int sh;         // normalisation: v >> sh (sh >= 0) or v << -sh
    uint32_t ct;    // the cumulative response's total
    int64_t w_q16;  // looks, Q16
    uint16_t evals;
    bool faded;     // a sample far below the model (deviance())
} ctx_t;

static int64_t mulsh(int64_t a, int64_t b, unsigned s);

static uint32_t nrm(const ctx_t *c, uint32_t v)
{
    if (c->sh >= 0) {
        return v >> (unsigned)c->sh;
    }
    return v << (unsigned)(-c->sh);
}

static uint32_t y_at(const ctx_t *c, uint32_t k)
{
    return nrm(c, c->in->y[k]);
}

static uint32_t f_at(const ctx_t *c, uint32_t k)
{
    const uint32_t f = nrm(c, (c->in->f != NULL) ? c->in->f[k] : c->in->floor);
    return (f == 0U) ? 1U : f;
}

// mass_q16 x 2^40 / (w_q8 x CT), saturating (a width of 1/256 bin under a one-tap response).
static int32_t piece_coef(const ctx_t *c, uint32_t mass_q16, int32_t w_q8)
{
    if (w_q8 < 1) {
        w_q8 = 1;
    }
    const uint64_t v = (((uint64_t)mass_q16) << 40) / ((uint64_t)(uint32_t)w_q8 * c->ct);
    return (v > INT32_MAX) ? INT32_MAX : (int32_t)v;
}

static void pieces_build(const ctx_t *c, int32_t a, int32_t b, pieces_t *p)
{
    if (c->in->shape != (uint8_t)SL_RFIT_FOOT) {
        p->np = 1U;
        p->x[0] = a;
        p->x[1] = b;
        p->dxa[0] = 65536;
        p->dxb[0] = 0;
        p->dxa[1] = 0;
        p->dxb[1] = 65536;
    } else {
        // Equal-mass pieces of g(X) ~ X / sqrt(X^2 - A0^2): M(X) = sqrt(X^2 - A0^2), so the
        // j-th breakpoint is X_j = sqrt(A0^2 + t^2 (B0^2 - A0^2)), t = j / P, with
        // d X_j / d A0 = A0 (1 - t^2) / X_j and d X_j / d B0 = t^2 B0 / X_j.
        const int64_t o = (int64_t)c->in->origin_q8;
        const int64_t a0 = o + a;
        const int64_t b0 = o + b;
        const uint64_t a2 = (uint64_t)(a0 * a0);
        const uint64_t m2 = (uint64_t)(b0 * b0) - a2;
        p->np = (uint8_t)SL_RFIT_PIECES;
        p->x[0] = a;
        p->dxa[0] = 65536;
        p->dxb[0] = 0;
        const uint64_t pp = (uint64_t)SL_RFIT_PIECES * SL_RFIT_PIECES;
        for (uint32_t i = 1; i < SL_RFIT_PIECES; i++) {
            const uint64_t t2 = (uint64_t)i * i; // t^2 x P^2
            const uint64_t xs = sl_fx_isqrt64(a2 + m2 * t2 / pp);
            p->x[i] = (int32_t)((int64_t)xs - o);
            if (p->x[i] < p->x[i - 1U]) {
                p->x[i] = p->x[i - 1U];
            }
            const uint64_t den = (xs == 0U) ? 1U : xs;
            p->dxa[i] = (int32_t)(((uint64_t)a0 * (pp - t2) * 65536U) / (pp * den));
            p->dxb[i] = (int32_t)(((uint64_t)b0 * t2 * 65536U) / (pp * den));
        }
        p->x[SL_RFIT_PIECES] = b;
        p->dxa[SL_RFIT_PIECES] = 0;
        p->dxb[SL_RFIT_PIECES] = 65536;
    }
    const uint32_t mass = 65536U / p->np;
    for (uint32_t i = 0; i < p->np; i++) {
        int32_t w = p->x[i + 1U] - p->x[i];
        w = (w < 1) ? 1 : w;
        p->coef[i] = piece_coef(c, mass, w);
        p->inv_w[i] = (uint32_t)(((uint64_t)1 << 32) / (uint32_t)w - (w == 1 ? 1U : 0U));
    }
}

// The model at sample k, Q24 of the return's total power, and (when dm_da and dm_db are
// given) its derivatives by a and b, Q24 per bin. A piece p adds
// coef_p (C(k - x_p) - C(k - x_p+1)); moving a breakpoint moves the piece's end (the
// response there, dC/du = SUB R) and its width (coef ~ 1 / width).
static int64_t model_at(const ctx_t *c, const pieces_t *p, uint32_t k, int64_t *dm_da,
                        int64_t *dm_db)
{
    const int32_t kq = (int32_t)(k * 256U);
    const bool grad = dm_da != NULL && dm_db != NULL;
    int64_t m = 0, ga = 0, gb = 0;
    uint32_t hi = sl_response_cum(c->r, kq - p->x[0]);
    int64_t r_hi = grad ? (int64_t)sl_response_at_q22(c->r, kq - p->x[0]) : 0;
    for (uint32_t i = 0; i < p->np; i++) {
        const uint32_t lo = sl_response_cum(c->r, kq - p->x[i + 1U]);
        const int64_t mp = (int64_t)p->coef[i] * (int64_t)(hi - lo); // Q48
        m += mp;
        hi = lo;
        if (grad) {
            const int64_t r_lo = (int64_t)sl_response_at_q22(c->r, kq - p->x[i + 1U]);
            // d/dx_i and d/dx_i+1 of this piece, Q24 per bin
            const int64_t wterm = sl_fx_rshift_round64(sl_fx_rshift_round64(mp, 24) * 256 *
                                                           (int64_t)p->inv_w[i], 32);
            // C(k - x) falls as x grows (dC/dx = -SUB R); the width grows with x_i+1
            const int64_t d_lo =
                wterm - sl_fx_rshift_round64((int64_t)p->coef[i] * SL_RESP_SUB * r_hi, 24);
            const int64_t d_hi =
                sl_fx_rshift_round64((int64_t)p->coef[i] * SL_RESP_SUB * r_lo, 24) - wterm;
            // |d| < 2^40 (the model is a fraction over widths >= 1/256 bin), |dx| <= 2^17
            ga += sl_fx_rshift_round64(d_lo * p->dxa[i] + d_hi * p->dxa[i + 1U], 16);
            gb += sl_fx_rshift_round64(d_lo * p->dxb[i] + d_hi * p->dxb[i + 1U], 16);
            r_hi = r_lo;
        }
    }
    if (dm_da != NULL && dm_db != NULL) {
        *dm_da = ga;
        *dm_db = gb;
    }
    return sl_fx_rshift_round64(m, 24);
}

static uint64_t mu_of(const ctx_t *c, uint64_t level, int64_t m_q24, uint32_t k)
{
    const uint64_t s = (m_q24 <= 0) ? 0U : sl_fx_urshift_round64(level * (uint64_t)m_q24, 24);
    const uint64_t mu = (uint64_t)f_at(c, k) + s;
    return (mu == 0U) ? 1U : mu;
}

// J = w sum (ln mu + y / mu), nats Q16 (relative to the normalisation).
static int64_t nll(ctx_t *c, const pieces_t *p, uint64_t level)
{
    c->evals++;
    int64_t acc = 0; // sum of ln mu + y/mu, Q16
    for (uint32_t k = 0; k < c->in->n; k++) {
        const uint64_t mu = mu_of(c, level, model_at(c, p, k, NULL, NULL), k);
        const int64_t ln = sl_fx_rshift_round64((int64_t)sl_lin_log2_q16(mu) * LN2_Q16, 16);
        acc += ln + (int64_t)((((uint64_t)y_at(c, k)) << 16) / mu);
    }
    return mulsh(acc, c->w_q16, 16);
}

static int64_t clampj(int64_t v)
{
    return (v > JT_MAX) ? JT_MAX : ((v < -JT_MAX) ? -JT_MAX : v);
}

// x / mu in Q14 (mu >= 1), clamped to +-JT_MAX.
static int64_t over_mu_q14(int64_t x, uint64_t mu)
{
    const int64_t lim = (int64_t)1 << 48;
    x = (x > lim) ? lim : ((x < -lim) ? -lim : x);
    const int64_t q = (x * 16384) / (int64_t)mu;
    return clampj(q);
}

// The model's Jacobian at sample k scaled by 1 / mu, Q14: j[0] = level m (by ln level),
// j[1] = level dm/da, j[2] = level dm/db (per bin); returns mu.
static uint64_t jacobian_at(const ctx_t *c, const pieces_t *p, uint64_t level, uint32_t k,
                            int64_t j[3])
{
    int64_t ma, mb;
    const int64_t m0 = model_at(c, p, k, &ma, &mb);
    const uint64_t mu = mu_of(c, level, m0, k);
    j[0] = over_mu_q14((int64_t)(mu - (uint64_t)f_at(c, k)), mu); // level x m0
    j[1] = over_mu_q14(mulsh((int64_t)level, ma, 24), mu);
    j[2] = over_mu_q14(mulsh((int64_t)level, mb, 24), mu);
    return mu;
}

// The Fisher information and score at (a, b, level), parameters (ln level, a, b) in
// (1, bins, bins).
static void normal_eq(ctx_t *c, int32_t a, int32_t b, uint64_t level, normal_t *ne)
{
    pieces_t *const p0 = &c->w->p;
    pieces_build(c, a, b, p0);
    memset(ne, 0, sizeof(*ne));
    int64_t g38[3] = {0, 0, 0}; // score, Q38
    for (uint32_t k = 0; k < c->in->n; k++) {
        int64_t j[3];
        const uint64_t mu = jacobian_at(c, p0, level, k, j);
        // the residual in Q24: near the optimum it is a few 1e-5 of mu per sample
        int64_t rt = (((int64_t)y_at(c, k) - (int64_t)mu) * 16777216) / (int64_t)mu;
        if (rt > ((int64_t)64 << 24)) {
            rt = (int64_t)64 << 24;
        }
        for (int i = 0; i < 3; i++) {
            for (int q = 0; q <= i; q++) {
                ne->n[i][q] += j[i] * j[q];
            }
            g38[i] += j[i] * rt;
        }
    }
    for (int i = 0; i < 3; i++) {
        ne->g[i] = sl_fx_rshift_round64(g38[i], 10);
    }
    for (int i = 0; i < 3; i++) {
        for (int q = i + 1; q < 3; q++) {
            ne->n[i][q] = ne->n[q][i];
        }
    }
}

static int64_t div_q16(int64_t num, int64_t den)
{
    if (den == 0) {
        return 0;
    }
    // |num| < 2^46 keeps num << 16 inside int64
    const int64_t lim = (int64_t)1 << 46;
    if (num > lim) {
        num = lim;
    } else if (num < -lim) {
        num = -lim;
    }
    return (num * 65536) / den;
}

static ldl_t factor(const normal_t *ne)
{
    ldl_t f;
    memset(&f, 0, sizeof(f));
    f.d[0] = ne->n[0][0];
    if (f.d[0] <= 0) {
        return f;
    }
    f.l10 = div_q16(ne->n[1][0], f.d[0]);
    f.l20 = div_q16(ne->n[2][0], f.d[0]);
    f.d[1] = ne->n[1][1] - sl_fx_rshift_round64(f.l10 * ne->n[1][0], 16);
    if (f.d[1] <= 0) {
        return f;
    }
    f.l21 = div_q16(ne->n[2][1] - sl_fx_rshift_round64(f.l20 * ne->n[1][0], 16), f.d[1]);
    f.d[2] = ne->n[2][2] - sl_fx_rshift_round64(f.l20 * ne->n[2][0], 16) -
             sl_fx_rshift_round64(f.l21 * sl_fx_rshift_round64(f.l21 * f.d[1], 16), 16);
    f.ok = f.d[2] > 0;
    return f;
}

// Solves N x = g; x in Q16 (ln level, bins, bins).
static void solve(const ldl_t *f, const int64_t g[3], int64_t x[3])
{
    const int64_t z0 = g[0];
    const int64_t z1 = g[1] - sl_fx_rshift_round64(f->l10 * z0, 16);
    const int64_t z2 = g[2] - sl_fx_rshift_round64(f->l20 * z0, 16) -
                       sl_fx_rshift_round64(f->l21 * z1, 16);
    const int64_t u0 = div_q16(z0, f->d[0]);
    const int64_t u1 = div_q16(z1, f->d[1]);
    const int64_t u2 = div_q16(z2, f->d[2]);
    x[2] = u2;
    x[1] = u1 - sl_fx_rshift_round64(f->l21 * x[2], 16);
    x[0] = u0 - sl_fx_rshift_round64(f->l10 * x[1], 16) - sl_fx_rshift_round64(f->l20 * x[2], 16);
}

static int32_t clamp_step(int64_t v_q8)
{
    if (v_q8 > MAX_STEP_Q8) {
        return MAX_STEP_Q8;
    }
    if (v_q8 < -MAX_STEP_Q8) {
        return -MAX_STEP_Q8;
    }
    return (int32_t)v_q8;
}

static void keep_inside(const ctx_t *c, int32_t *a, int32_t *b)
{
    const int32_t hi = (int32_t)(c->in->n - 1U) * 256;
    if (*a < 0) {
        *a = 0;
    }
    if (*a > hi - MIN_W_Q8) {
        *a = hi - MIN_W_Q8;
    }
    if (*b > hi) {
        *b = hi;
    }
    if (*b < *a + MIN_W_Q8) {
        *b = *a + MIN_W_Q8;
    }
}

// level x e^(dl), dl in Q16 nats, |dl| <= 2: a cubic Taylor series for |dl| <= 1/4 (error
// below 2e-4 relative, exact to Q16 for the small steps near convergence), 2^(dl / ln 2)
// through the lp table beyond.
static uint64_t scale_level(uint64_t level, int64_t dl_q16)
{
    if (dl_q16 > 2 * 65536) {
        dl_q16 = 2 * 65536;
    } else if (dl_q16 < -2 * 65536) {
        dl_q16 = -2 * 65536;
    }
    uint64_t s;
    if (dl_q16 <= 16384 && dl_q16 >= -16384) {
        const int64_t d2 = sl_fx_rshift_round64(dl_q16 * dl_q16, 16);
        const int64_t d3 = sl_fx_rshift_round64(d2 * dl_q16, 16);
        s = (uint64_t)(65536 + dl_q16 + d2 / 2 + d3 / 6);
    } else {
        s = sl_lp_to_lin_q16((int32_t)((dl_q16 * 256) / LN2_Q16));
    }
    const uint64_t v =
        (level > (LEVEL_MAX << 16) / s) ? LEVEL_MAX : sl_fx_urshift_round64(level * s, 16);
    return (v == 0U) ? 1U : ((v > LEVEL_MAX) ? LEVEL_MAX : v);
}

// Start from the moments of the power above the floor around the peak (-18 dB region).
static bool start(const ctx_t *c, int32_t *a, int32_t *b, uint64_t *level)
{
    uint32_t ip = 0, ymax = 0;
    for (uint32_t k = 0; k < c->in->n; k++) {
        if (y_at(c, k) > ymax) {
            ymax = y_at(c, k);
            ip = k;
        }
    }
    uint32_t lo = ip, hi = ip;
    while (lo > 0U && y_at(c, lo - 1U) >= ymax / 64U) {
        lo--;
    }
    while (hi + 1U < c->in->n && y_at(c, hi + 1U) >= ymax / 64U) {
        hi++;
    }
    uint64_t s0 = 0, s1 = 0, s2 = 0;
    for (uint32_t k = lo; k <= hi; k++) {
        const uint32_t y = y_at(c, k), f = f_at(c, k);
        const uint64_t e = (y > f) ? (uint64_t)(y - f) : 0U;
        s0 += e;
        s1 += e * k;
        s2 += e * k * k;
    }
    if (s0 == 0U) {
        return false;
    }
    const uint64_t c_q8 = (s1 * 256U) / s0;
    const uint64_t m2_q16 = (s2 * 65536U) / s0;
    const uint64_t c2_q16 = c_q8 * c_q8;
    // the response's own variance over the taps above 1/64 of its peak, Q16
    uint64_t t0 = 0, t2 = 0;
    for (int i = 0; i < SL_RESP_TAPS; i++) {
        const uint32_t t = c->r->tap_q22[i] >> 7;
        if (t >= 512U) {
            const int64_t o = (int64_t)i - (int64_t)SL_CFG_RESP_HALF;
            t0 += t;
            t2 += (uint64_t)t * (uint64_t)(o * o);
        }
    }
    const uint64_t vr_q16 = (t0 == 0U) ? 0U : (t2 * 65536U) / t0;
    const uint64_t v_q16 = (m2_q16 > c2_q16) ? m2_q16 - c2_q16 : 0U;
    uint64_t w2_q16 = (v_q16 > vr_q16) ? 12U * (v_q16 - vr_q16) : 0U;
    if (w2_q16 < 65536U) {
        w2_q16 = 65536U;
    }
    const int32_t w_q8 = (int32_t)sl_fx_isqrt64(w2_q16);
    *a = (int32_t)c_q8 - w_q8 / 2;
    *b = *a + w_q8;
    if (c->in->warm != 0U) {
        *a = c->in->a0_q8;
        *b = c->in->b0_q8;
    }
    *level = s0;
    return true;
}

// a x b >> s for signed values, saturating at +-2^61 (a sum of two stays inside int64).
static int64_t mulsh(int64_t a, int64_t b, unsigned s)
{
    const uint64_t lim = (uint64_t)1 << 61;
    const bool neg = (a < 0) != (b < 0);
    const uint64_t ua = (a < 0) ? (uint64_t)0 - (uint64_t)a : (uint64_t)a;
    const uint64_t ub = (b < 0) ? (uint64_t)0 - (uint64_t)b : (uint64_t)b;
    if (ua != 0U && ub > lim / ua) {
        return neg ? -(int64_t)lim : (int64_t)lim;
    }
    return sl_fx_rshift_round64(a * b, s);
}

#define SAT ((int64_t)1 << 61)

// v x 256 / looks_q8 without losing a small v's digits or overflowing a large one.
static int64_t per_looks(int64_t v, uint16_t looks_q8)
{
    const int64_t lim = (int64_t)1 << 52;
    if (v < lim && v > -lim) {
        return (v * 256) / (int64_t)looks_q8;
    }
    return (v / (int64_t)looks_q8) * 256;
}

// The bounds' covariance: the sandwich N^-1 M N^-1 of the independence likelihood, M the
// score's covariance under the speckle's correlation between bins (rho2 of sl_response.h),
// for (a, b) with the level profiled out (the Jacobian projected off the level's column).
static void covariance(ctx_t *c, int32_t a, int32_t b, uint64_t level, const ldl_t *f,
                       sl_rfit_out_t *out)
{
    out->sigma_a_q8 = UINT32_MAX;
    out->sigma_b_q8 = UINT32_MAX;
    out->corr_q15 = 0;
    // G = the Schur complement's inverse, per look, bins^2 Q16: var_b = 1/d2,
    // var_a = 1/d1 + l21^2/d2, cov = -l21/d2 (d Q28: 2^44 / d)
    const int64_t one = (int64_t)1 << 44;
    const int64_t g_b = one / f->d[2];
    const int64_t g_a = one / f->d[1] + mulsh(mulsh(g_b, f->l21, 16), f->l21, 16);
    const int64_t g_ab = -mulsh(g_b, f->l21, 16);
    if (g_a >= SAT || g_b >= SAT) {
        return;
    }
    pieces_t *const p0 = &c->w->p;
    pieces_build(c, a, b, p0);
    int16_t *const ra = c->w->ra; // projected Jacobians of the last RING samples, Q10
    int16_t *const rb = c->w->rb;
    int64_t m_aa = 0, m_bb = 0, m_ab = 0; // Q28 (Q10 x Q10 x Q15 >> 7)
    for (uint32_t k = 0; k < c->in->n; k++) {
        int64_t j[3];
        (void)jacobian_at(c, p0, level, k, j);
        int64_t ta = sl_fx_rshift_round64(j[1] - sl_fx_rshift_round64(f->l10 * j[0], 16), 4);
        int64_t tb = sl_fx_rshift_round64(j[2] - sl_fx_rshift_round64(f->l20 * j[0], 16), 4);
        ta = (ta > 32767) ? 32767 : ((ta < -32767) ? -32767 : ta);
        tb = (tb > 32767) ? 32767 : ((tb < -32767) ? -32767 : tb);
        const uint32_t slot = k % RING;
        ra[slot] = (int16_t)ta;
        rb[slot] = (int16_t)tb;
        const uint32_t lags = (k < RING - 1U) ? k : RING - 1U;
        for (uint32_t d = 0; d <= lags; d++) {
            const uint32_t s = (k - d) % RING;
            const int64_t w = c->r->rho2_q15[d];
            const int64_t f2 = (d == 0U) ? (int64_t)1 : (int64_t)2; // both orders of a pair
            m_aa += f2 * ((ta * ra[s] * w) >> 7);
            m_bb += f2 * ((tb * rb[s] * w) >> 7);
            m_ab += (d == 0U) ? ((ta * tb * w) >> 7) : (((ta * rb[s] + tb * ra[s]) * w) >> 7);
        }
    }
    // M in Q16
    const int64_t Maa = sl_fx_rshift_round64(m_aa, 12);
    const int64_t Mbb = sl_fx_rshift_round64(m_bb, 12);
    const int64_t Mab = sl_fx_rshift_round64(m_ab, 12);
    // P = G M (Q16), C = P G (Q16)
    const int64_t p_aa = mulsh(g_a, Maa, 16) + mulsh(g_ab, Mab, 16);
    const int64_t p_ab = mulsh(g_a, Mab, 16) + mulsh(g_ab, Mbb, 16);
    const int64_t p_ba = mulsh(g_ab, Maa, 16) + mulsh(g_b, Mab, 16);
    const int64_t p_bb = mulsh(g_ab, Mab, 16) + mulsh(g_b, Mbb, 16);
    int64_t c_aa = mulsh(p_aa, g_a, 16) + mulsh(p_ab, g_ab, 16);
    int64_t c_bb = mulsh(p_ba, g_ab, 16) + mulsh(p_bb, g_b, 16);
    int64_t c_ab = mulsh(p_aa, g_ab, 16) + mulsh(p_ab, g_b, 16);
    // per look -> the looks averaged (a small variance keeps its digits: multiplied first)
    c_aa = per_looks(c_aa, c->in->looks_q8);
    c_bb = per_looks(c_bb, c->in->looks_q8);
    c_ab = per_looks(c_ab, c->in->looks_q8);
    if (c_aa <= 0 || c_bb <= 0 || c_aa >= SAT / 2 || c_bb >= SAT / 2) {
        return;
    }
    out->sigma_a_q8 = sl_fx_isqrt64((uint64_t)c_aa);
    out->sigma_b_q8 = sl_fx_isqrt64((uint64_t)c_bb);
    if (out->sigma_a_q8 != 0U && out->sigma_b_q8 != 0U) {
        const int64_t den = (int64_t)out->sigma_a_q8 * (int64_t)out->sigma_b_q8; // < 2^62
        int64_t corr;
        if (c_ab >= den || -c_ab >= den) {
            corr = (c_ab < 0) ? (int64_t)-32767 : (int64_t)32767; // rounding at |corr| = 1
        } else if (den < ((int64_t)1 << 40)) {
            corr = (c_ab * 32768) / den;
        } else {
            corr = c_ab / (den >> 15);
        }
        corr = (corr > 32767) ? 32767 : ((corr < -32767) ? -32767 : corr);
        out->corr_q15 = (int32_t)corr;
    }
}

static void deviance(ctx_t *c, int32_t a, int32_t b, uint64_t level, sl_rfit_out_t *out)
{
    pieces_t *const p = &c->w->p;
    pieces_build(c, a, b, p);
    int64_t d = 0; // Q16
    int64_t rmin = INT64_MAX; // the smallest y / mu, Q16
    for (uint32_t k = 0; k < c->in->n; k++) {
        const uint64_t mu = mu_of(c, level, model_at(c, p, k, NULL, NULL), k);
        uint32_t y = y_at(c, k);
        if (y == 0U) {
            y = 1U;
        }
        const int64_t ratio = (int64_t)((((uint64_t)y) << 16) / mu);
        rmin = ratio < rmin ? ratio : rmin;
        const int64_t ln = sl_fx_rshift_round64(
            ((int64_t)sl_lin_log2_q16(y) - (int64_t)sl_lin_log2_q16(mu)) * LN2_Q16, 16);
        d += ratio - 65536 - ln;
    }
    // D = 2 w sum(...), Q8
    const int64_t dq = mulsh(2 * d, c->w_q16, 24);
    out->dev_q8 = (dq < 0) ? 0U : sl_fx_usat32(dq);
    // E = n (1 + 1 / (6 looks)); Var ~ 2 n s4 (the terms correlate as rho2^2); limit
    // E + 6 sqrt(Var) + 8
    const uint64_t e_q8 = (uint64_t)c->in->n * (1536U * c->in->looks_q8 + 65536U) /
                          (6U * c->in->looks_q8);
    const uint64_t sq_q8 = sl_fx_isqrt64(2U * (uint64_t)c->in->n * c->r->s4_q8 * 256U);
    const uint64_t lim = e_q8 + 6U * sq_q8 + 8U * 256U;
    out->dev_limit_q8 = (lim > UINT32_MAX) ? UINT32_MAX : (uint32_t)lim;
    // A fade: one look's power falls below x of its mean with probability 1 - e^-x ~ x, so
    // over the window's n / ncorr independent cells a sample below FADE_P ncorr / n of the
    // model happens by speckle with probability FADE_P at most (more looks: less still).
    const uint64_t cells_q8 = 256U * (uint64_t)c->in->n; // n >= 8 (sl_rfit_ws)
    const uint64_t fade_q16 =
        ((uint64_t)FADE_P_Q16 * c->r->ncorr_q8) / (cells_q8 == 0U ? 1U : cells_q8);
    c->faded = rmin < (int64_t)fade_q16;
    const uint64_t disp = (e_q8 == 0U) ? 256U : ((uint64_t)out->dev_q8 * 256U) / e_q8;
    out->dispersion_q8 = (disp < 256U) ? 256U : ((disp > UINT32_MAX) ? UINT32_MAX : (uint32_t)disp);
}

// Sigmas scaled by sqrt(dispersion) (quasi-likelihood), saturating.
static uint32_t disperse(uint32_t sigma_q8, uint32_t disp_q8)
{
    if (sigma_q8 == UINT32_MAX) {
        return sigma_q8;
    }
    const uint64_t r_q8 = sl_fx_isqrt64((uint64_t)disp_q8 * 256U); // sqrt(disp), Q8
    const uint64_t v = ((uint64_t)sigma_q8 * r_q8 + 128U) >> 8;
    return (v >= UINT32_MAX) ? UINT32_MAX : (uint32_t)v;
}

// The shift that brings the window's largest power (observed or floor) to ~2^NORM_BITS;
// returns the observed maximum's bit length (0: no power at all).
static int normalise(ctx_t *c)
{
    uint32_t ymax = 0, vmax = 0;
    for (uint32_t k = 0; k < c->in->n; k++) {
        const uint32_t f = (c->in->f != NULL) ? c->in->f[k] : c->in->floor;
        ymax = (c->in->y[k] > ymax) ? c->in->y[k] : ymax;
        vmax = (f > vmax) ? f : vmax;
    }
    vmax = (ymax > vmax) ? ymax : vmax;
    int bits = 0;
    while (bits < 32 && (vmax >> bits) != 0U) {
        bits++;
    }
    c->sh = bits - NORM_BITS;
    return (ymax == 0U) ? 0 : bits;
}

// One Fisher step from (a, b, level) with the step halved while J grows; returns true when
// the fit is done (the step below the bounds' resolution, or no descent left).
static bool fisher_step(ctx_t *c, const normal_t *ne, const ldl_t *f, int32_t *a, int32_t *b,
                        uint64_t *level, int64_t *j, bool *converged)
{
    int64_t x[3];
    solve(f, ne->g, x);
    int32_t da = clamp_step(sl_fx_rshift_round64(x[1], 8));
    int32_t db = clamp_step(sl_fx_rshift_round64(x[2], 8));
    int64_t dl = x[0];
    if (sl_fx_abs32(da) < TOL_Q8 && sl_fx_abs32(db) < TOL_Q8 && dl < 655 && dl > -655) {
        *converged = true; // the step is below the bounds' resolution
        return true;
    }
    pieces_t *const p = &c->w->p;
    bool small = false; // what is left of the step is below the resolution
    for (int h = 0; h <= SL_RFIT_HALVINGS && !small; h++) {
        int32_t na = *a + da, nb = *b + db;
        keep_inside(c, &na, &nb);
        const uint64_t nl = scale_level(*level, dl);
        pieces_build(c, na, nb, p);
        const int64_t jn = nll(c, p, nl);
        if (jn <= *j) {
            *a = na;
            *b = nb;
            *level = nl;
            *j = jn;
            return false;
        }
        da /= 2;
        db /= 2;
        dl /= 2;
        small = sl_fx_abs32(da) < TOL_Q8 && sl_fx_abs32(db) < TOL_Q8 && dl < 655 && dl > -655;
    }
    *converged = true; // no descent left at the objective's resolution
    return true;
}

sl_err_t sl_rfit(const sl_response_t *r, const sl_rfit_in_t *in, sl_rfit_out_t *out)
{
    sl_rfit_ws_t ws;
    return sl_rfit_ws(r, in, &ws, out);
}

sl_err_t sl_rfit_ws(const sl_response_t *r, const sl_rfit_in_t *in, sl_rfit_ws_t *ws,
                    sl_rfit_out_t *out)
{
    if (r == NULL || in == NULL || out == NULL || ws == NULL || in->y == NULL || in->n < 8U ||
        in->n > SL_RFIT_MAX_N || in->looks_q8 < 256U || (in->f == NULL && in->floor == 0U) ||
        in->shape > (uint8_t)SL_RFIT_FOOT ||
        (in->shape == (uint8_t)SL_RFIT_FOOT && in->origin_q8 == 0U)) {
        return SL_ERR_ARG;
    }
    memset(out, 0, sizeof(*out));
    ctx_t c;
    memset(&c, 0, sizeof(c));
    c.w = (work_t *)(void *)ws; // MISRA 11.5 (docs/MISRA.md): the opaque workspace's layout
    c.r = r;
    c.in = in;
    c.ct = r->cum[SL_RESP_CUM - 1];
    c.w_q16 = (int64_t)in->looks_q8 * 256;
    if (c.ct == 0U || c.w_q16 <= 0 || normalise(&c) == 0) {
        out->quality = (uint8_t)SL_RFIT_NO_SIGNAL;
        return SL_OK;
    }
    int32_t a, b;
    uint64_t level;
    if (!start(&c, &a, &b, &level)) {
        out->quality = (uint8_t)SL_RFIT_NO_SIGNAL;
        return SL_OK;
    }
    keep_inside(&c, &a, &b);
    pieces_build(&c, a, b, &c.w->p);
    int64_t j = nll(&c, &c.w->p, level);
    bool converged = false;
    bool fresh = false; // ne and f hold the information at (a, b, level)
    normal_t *const ne = &c.w->ne;
    ldl_t *const f = &c.w->f;
    uint8_t it = 0;
    bool done = false;
    for (; it < SL_RFIT_ITERS && !done; it++) {
        normal_eq(&c, a, b, level, ne);
        *f = factor(ne);
        fresh = true; // ne and f are the information at (a, b, level) until a step moves it
        if (!f->ok) {
            done = true;
        } else {
            done = fisher_step(&c, ne, f, &a, &b, &level, &j, &converged);
            fresh = done;
        }
    }
    if (!fresh) {
        normal_eq(&c, a, b, level, ne);
        *f = factor(ne);
    }
    out->a_q8 = a;
    out->b_q8 = b;
    out->iters = it;
    out->nll_q16 = j;
    if (f->ok) {
        covariance(&c, a, b, level, f, out);
    } else {
        out->sigma_a_q8 = UINT32_MAX;
        out->sigma_b_q8 = UINT32_MAX;
    }
    // the level in the caller's scale (total power: undo the normalisation)
    out->level = (c.sh >= 0) ? sl_fx_usat32((int64_t)(level << (unsigned)c.sh))
                             : sl_fx_usat32((int64_t)(level >> (unsigned)(-c.sh)));
    deviance(&c, a, b, level, out);
    out->sigma_a_q8 = disperse(out->sigma_a_q8, out->dispersion_q8);
    out->sigma_b_q8 = disperse(out->sigma_b_q8, out->dispersion_q8);
    out->evals = c.evals;
    if (out->dev_q8 > out->dev_limit_q8 || c.faded) {
        out->quality = (uint8_t)SL_RFIT_OUT_OF_MODEL;
    } else if (!converged) {
        out->quality = (uint8_t)SL_RFIT_NOT_CONVERGED;
    } else {
        out->quality = (uint8_t)SL_RFIT_OK;
    }
    return SL_OK;
}

sl_err_t sl_rfit_model(const sl_response_t *r, uint8_t shape, uint32_t origin_q8, int32_t a_q8,
                       int32_t b_q8, uint16_t n, uint32_t *m_q16)
{
    if (r == NULL || m_q16 == NULL || n == 0U || n > SL_RFIT_MAX_N || b_q8 < a_q8 ||
        shape > (uint8_t)SL_RFIT_FOOT || (shape == (uint8_t)SL_RFIT_FOOT && origin_q8 == 0U)) {
        return SL_ERR_ARG;
    }
    sl_rfit_in_t in;
    memset(&in, 0, sizeof(in));
    in.shape = shape;
    in.origin_q8 = origin_q8;
    in.n = n;
    ctx_t c;
    memset(&c, 0, sizeof(c));
    c.r = r;
    c.in = &in;
    c.ct = r->cum[SL_RESP_CUM - 1];
    if (c.ct == 0U) {
        return SL_ERR_ARG;
    }
    pieces_t p; // the model alone: no workspace
    pieces_build(&c, a_q8, (b_q8 - a_q8 < 1) ? a_q8 + 1 : b_q8, &p);
    for (uint32_t k = 0; k < n; k++) {
        const int64_t m = sl_fx_rshift_round64(model_at(&c, &p, k, NULL, NULL), 8);
        m_q16[k] = (m < 0) ? 0U : sl_fx_usat32(m);
    }
    return SL_OK;
}
