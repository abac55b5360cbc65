// SPDX-License-Identifier: MIT
/// @file tilt.c
/// @brief 3D pole tilt from in-plane inclinations over the vehicle's motion (sl_tilt.h).
#include "shadowlean/sl_tilt.h"

#include <string.h>

#include "compiler.h"

// sin(i * 90 deg / 256) for i = 0..256, Q30, rounded to nearest:
//   python3 -c "import math; print([int(math.floor(math.sin(i*math.pi/512)*2**30+0.5))
//               for i in range(257)])"
static const int32_t sin_q30_tab[257] = {
    0, 6588356, 13176464, 19764076, 26350943, 32936819,
    39521455, 46104602, 52686014, 59265442, 65842639, 72417357,
    78989349, 85558366, 92124163, 98686491, 105245103, 111799753,
    118350194, 124896179, 131437462, 137973796, 144504935, 151030634,
    157550647, 164064728, 170572633, 177074115, 183568930, 190056834,
    196537583, 203010932, 209476638, 215934457, 222384147, 228825464,
    235258165, 241682010, 248096755, 254502159, 260897982, 267283981,
    273659918, 280025552, 286380643, 292724951, 299058239, 305380268,
    311690799, 317989595, 324276419, 330551034, 336813204, 343062693,
    349299266, 355522689, 361732726, 367929144, 374111709, 380280190,
    386434353, 392573967, 398698801, 404808624, 410903207, 416982319,
    423045732, 429093217, 435124548, 441139496, 447137835, 453119340,
    459083786, 465030947, 470960600, 476872522, 482766489, 488642281,
    494499676, 500338453, 506158392, 511959275, 517740883, 523502998,
    529245404, 534967884, 540670223, 546352205, 552013618, 557654248,
    563273883, 568872310, 574449320, 580004702, 585538248, 591049748,
    596538995, 602005783, 607449906, 612871159, 618269338, 623644239,
    628995660, 634323400, 639627258, 644907034, 650162530, 655393548,
    660599890, 665781362, 670937767, 676068911, 681174602, 686254647,
    691308855, 696337036, 701339000, 706314559, 711263525, 716185713,
    721080937, 725949013, 730789757, 735602987, 740388522, 745146182,
    749875788, 754577161, 759250125, 763894504, 768510122, 773096806,
    777654384, 782182683, 786681534, 791150767, 795590213, 799999706,
    804379079, 808728167, 813046808, 817334838, 821592095, 825818421,
    830013654, 834177638, 838310216, 842411232, 846480531, 850517961,
    854523370, 858496606, 862437520, 866345964, 870221790, 874064853,
    877875009, 881652112, 885396022, 889106597, 892783698, 896427186,
    900036924, 903612776, 907154608, 910662286, 914135678, 917574653,
    920979082, 924348837, 927683790, 930983817, 934248793, 937478595,
    940673101, 943832191, 946955747, 950043650, 953095785, 956112036,
    959092290, 962036435, 964944360, 967815955, 970651112, 973449725,
    976211688, 978936898, 981625251, 984276646, 986890984, 989468165,
    992008094, 994510675, 996975812, 999403415, 1001793390, 1004145648,
    1006460100, 1008736660, 1010975242, 1013175761, 1015338134, 1017462281,
    1019548121, 1021595575, 1023604567, 1025575020, 1027506862, 1029400018,
    1031254418, 1033069992, 1034846671, 1036584389, 1038283080, 1039942680,
    1041563127, 1043144360, 1044686319, 1046188946, 1047652185, 1049075980,
    1050460278, 1051805027, 1053110176, 1054375676, 1055601479, 1056787540,
    1057933813, 1059040255, 1060106826, 1061133483, 1062120190, 1063066909,
    1063973603, 1064840240, 1065666786, 1066453210, 1067199483, 1067905576,
    1068571464, 1069197120, 1069782521, 1070327646, 1070832474, 1071296985,
    1071721163, 1072104991, 1072448455, 1072751542, 1073014240, 1073236540,
    1073418433, 1073559913, 1073660973, 1073721611, 1073741824,
};

// sin of f in [0, 2^30] (a quarter turn in bam32 units), Q30: table + linear interpolation.
static int32_t sin_quarter(uint32_t f)
{
    const uint32_t idx = f >> 22;
    if (idx >= 256U) {
        return sin_q30_tab[256];
    }
    const int64_t s0 = sin_q30_tab[idx];
    const int64_t s1 = sin_q30_tab[idx + 1U];
    const int64_t rem = (int64_t)(f & 0x3FFFFFU);
    return (int32_t)(s0 + sl_fx_rshift_round64((s1 - s0) * rem, 22U));
}

void sl_tilt_sincos_q30(sl_bam32_t a, sl_q30_t *s, sl_q30_t *c)
{
    const uint32_t f = a & 0x3FFFFFFFU;
    const int32_t sf = sin_quarter(f);
    const int32_t cf = sin_quarter(0x40000000U - f);
    int32_t sv;
    int32_t cv;
    switch (a >> 30) {
    case 0U: sv = sf; cv = cf; break;
    case 1U: sv = cf; cv = -sf; break;
    case 2U: sv = -sf; cv = -cf; break;
    default: sv = -cf; cv = sf; break;
    }
    if (s != NULL) {
        *s = sv;
    }
    if (c != NULL) {
        *c = cv;
    }
}

// round(num / den) for den > 0, any sign of num.
static int64_t div_round(int64_t num, int64_t den)
{
    return (num >= 0) ? (num + den / 2) / den : -((-num + den / 2) / den);
}

// tan of a signed binary angle with |a| < 80 deg, Q12 (|tan| < 5.68).
static int16_t tan_q12(sl_bam32_t a)
{
    sl_q30_t s;
    sl_q30_t c;
    sl_tilt_sincos_q30(a, &s, &c);
    return sl_fx_sat16(sl_fx_sat32(div_round((int64_t)s * 4096, (int64_t)c)));
}

#define BAM_80_DEG 954437177 // 80 / 360 * 2^32
// Powers of two as constants (not shifts of a signed one: MISRA 10.1).
#define P2_24 ((int64_t)0x1000000)    // 2^24
#define P2_29 ((int64_t)0x20000000)   // 2^29
#define P2_30 ((int64_t)0x40000000)   // 2^30
#define P2_32 ((int64_t)4294967296LL) // 2^32
#define SIGMA_RAD_Q32_PER_CDEG 749613U // pi / 18000 * 2^32
#define R1_MAX_UM 1000000000U           // 1 km: beyond it the input is not a shadow target

bool sl_tilt_obs_make(sl_tilt_obs_t *out, int32_t radar_x_um, int32_t radar_y_um,
                      sl_bam32_t bearing_bam32, uint32_t r1_um, sl_bam32_t alpha_bam32,
                      uint16_t alpha_sigma_cdeg, uint8_t branch, const sl_incline_geom_t *geom)
{
    if (out == NULL) {
        return false;
    }
    memset(out, 0, sizeof *out);
    const int32_t a = (int32_t)alpha_bam32;
    if (geom == NULL || r1_um == 0U || r1_um > R1_MAX_UM || a >= BAM_80_DEG || a <= -BAM_80_DEG) {
        return false;
    }
    sl_q30_t s;
    sl_q30_t c;
    sl_tilt_sincos_q30(bearing_bam32, &s, &c);
    const int16_t t = tan_q12(alpha_bam32);
    int16_t tm = t;
    uint8_t mirrorable = 0U;
    // Branch 2, or branch 1 within two sigma of the seam (noise crosses it): the fold.
    const int64_t sigma_bam = (int64_t)alpha_sigma_cdeg * 119305; // 2^32 / 36000
    const int64_t above_seam = (int64_t)(int32_t)(alpha_bam32 - geom->beta_bam32);
    if (branch == (uint8_t)SL_INCLINE_BRANCH_2 ||
        (branch == (uint8_t)SL_INCLINE_BRANCH_1 && above_seam < 2 * sigma_bam)) {
        // The fold: alpha' = beta - theta - alpha reads the same rho (sl_incline.h).
        const sl_bam32_t am = geom->beta_bam32 - geom->theta_bam32 - alpha_bam32;
        const int32_t ams = (int32_t)am;
        if (ams < BAM_80_DEG && ams > -BAM_80_DEG) {
            tm = tan_q12(am);
            mirrorable = 1U;
        }
    }
    // sigma of tan(alpha) = sigma_alpha (rad) * (1 + tan^2), Q16.
    const uint64_t sa_q32 = (uint64_t)alpha_sigma_cdeg * SIGMA_RAD_Q32_PER_CDEG;
    const uint64_t sec2_q12 = 4096U + (uint64_t)((int32_t)t * (int32_t)t) / 4096U;
    uint64_t sig_q16 = (sa_q32 * sec2_q12) >> 28; // Q32 * Q12 -> Q16
    if (sig_q16 < SL_TILT_SIGMA_MIN_Q16) {
        sig_q16 = SL_TILT_SIGMA_MIN_Q16;
    }
    if (sig_q16 > UINT16_MAX) {
        sig_q16 = UINT16_MAX;
    }
    out->radar_x_um = radar_x_um;
    out->radar_y_um = radar_y_um;
    out->r1_um = r1_um;
    out->cos_a_q15 = sl_fx_sat16(sl_fx_sat32(sl_fx_rshift_round64(c, 15U)));
    out->sin_a_q15 = sl_fx_sat16(sl_fx_sat32(sl_fx_rshift_round64(s, 15U)));
    out->tan_q12 = t;
    out->tan_mirror_q12 = tm;
    out->sigma_q16 = (uint16_t)sig_q16;
    out->mirrorable = mirrorable;
    return true;
}

// ---------------------------------------------------------------------------------------
// The fit.
//
// Which branch-2 measurements are mirrored is not free: the in-plane inclination over the
// bearing a is tan(alpha) = -|t| cos(a - phi), below the fold exactly on one arc of bearings
// around phi. So, in bearing order, the mirrored measurements form one circular interval of
// the mirrorable ones. Every interval is a candidate (m(m-1) + 2 of them for m mirrorable
// measurements); each is scored in O(1) from prefix sums, without a division: for the
// least-squares optimum, sum(w r^2) / W = s - g' M^-1 g with g = (u, v) and M the bearing
// moment matrix, so det * that = s det - (c u^2 - 2 b u v + a v^2) ranks the candidates.

typedef struct cand_score {
    int64_t r_q54;  // s det - g' adj(M) g: sum(w r^2) / W * det, Q54
    size_t start;   // interval in bearing order
    size_t len;
} cand_score_t;

typedef struct fit_ctx {
    const sl_tilt_obs_t *obs;
    size_t n;
    sl_tilt_work_t *wk;
    size_t m;                 // mirrorable measurements (wk->order[0..m))
    int64_t w_sum_q16;
    uint16_t sigma_min_q16;
    sl_q30_t a_q30;           // normalised bearing moments
    sl_q30_t b_q30;
    sl_q30_t c_q30;
    int64_t det_q30;          // a c - b^2, Q30
    int64_t u0_q24;           // all as measured: mean(w c T), mean(w s T), mean(w T^2)
    int64_t v0_q24;
    int64_t s0_q24;
} fit_ctx_t;

static uint16_t obs_sigma(const sl_tilt_obs_t *o)
{
    return (o->sigma_q16 < SL_TILT_SIGMA_MIN_Q16) ? (uint16_t)SL_TILT_SIGMA_MIN_Q16 : o->sigma_q16;
}

// Relative weight of measurement k, (sigma_min / sigma_k)^2, Q16 (1 .. 2^16): recomputed
// where it is needed (one 32-bit division) rather than kept in the scratch memory.
static int64_t weight_q16(const fit_ctx_t *f, size_t k)
{
    const uint32_t r_q16 = ((uint32_t)f->sigma_min_q16 << 16) / obs_sigma(&f->obs[k]); // <= 1.0
    const uint32_t w = (uint32_t)(((uint64_t)r_q16 * r_q16) >> 16);
    return (w == 0U) ? 1 : (int64_t)w;
}

// Predicted tan(alpha) = -(t . e), Q12.
static int32_t predict_q12(const sl_tilt_obs_t *o, int32_t tx_q24, int32_t ty_q24)
{
    const int64_t d = (int64_t)tx_q24 * o->cos_a_q15 + (int64_t)ty_q24 * o->sin_a_q15; // Q39
    return sl_fx_sat32(-sl_fx_rshift_round64(d, 27U));
}

static int64_t score(const fit_ctx_t *f, int64_t u, int64_t v, int64_t s)
{
    const int64_t uu = sl_fx_rshift_round64(u * u, 24U);
    const int64_t uv = sl_fx_rshift_round64(u * v, 24U);
    const int64_t vv = sl_fx_rshift_round64(v * v, 24U);
    return s * f->det_q30 - ((int64_t)f->c_q30 * uu - 2 * (int64_t)f->b_q30 * uv +
                             (int64_t)f->a_q30 * vv);
}

// t = -M^-1 g, Q24.
static void solve_t(const fit_ctx_t *f, int64_t u, int64_t v, int32_t *tx, int32_t *ty)
{
    *tx = sl_fx_sat32(-div_round((int64_t)f->c_q30 * u - (int64_t)f->b_q30 * v, f->det_q30));
    *ty = sl_fx_sat32(-div_round((int64_t)f->a_q30 * v - (int64_t)f->b_q30 * u, f->det_q30));
}

// Calls `visit` for every candidate interval with its (u, v, s). Returns nothing; the
// visitor keeps what it needs.
typedef void (*visit_fn)(const fit_ctx_t *f, void *ctx, size_t start, size_t len, int64_t u,
                         int64_t v, int64_t s);

static void enumerate(const fit_ctx_t *f, visit_fn visit, void *ctx)
{
    const sl_tilt_work_t *wk = f->wk;
    visit(f, ctx, 0U, 0U, f->u0_q24, f->v0_q24, f->s0_q24);
    for (size_t i = 0; i < f->m; ++i) {
        int64_t u = f->u0_q24;
        int64_t v = f->v0_q24;
        int64_t s = f->s0_q24;
        for (size_t len = 1; len < f->m; ++len) {
            size_t j = i + len - 1U; // circular index without a division (i, len < m)
            j = (j >= f->m) ? j - f->m : j;
            u += wk->du_q24[j];
            v += wk->dv_q24[j];
            s += wk->ds_q24[j];
            visit(f, ctx, i, len, u, v, s);
        }
    }
    if (f->m > 0U) {
        int64_t u = f->u0_q24;
        int64_t v = f->v0_q24;
        int64_t s = f->s0_q24;
        for (size_t j = 0; j < f->m; ++j) {
            u += wk->du_q24[j];
            v += wk->dv_q24[j];
            s += wk->ds_q24[j];
        }
        visit(f, ctx, 0U, f->m, u, v, s);
    }
}

// The scores carry the Q24 rounding of the prefix sums (about 0.1 in chi-square), so pass 1
// keeps the TOP_K best and each of them is then solved and scored exactly from the
// measurements themselves.
#define TOP_K SL_TILT_TOP_K

typedef struct top_k {
    cand_score_t c[TOP_K];
    size_t n;
} top_k_t;

static void visit_best(const fit_ctx_t *f, void *ctx, size_t start, size_t len, int64_t u,
                       int64_t v, int64_t s)
{
    top_k_t *top = (top_k_t *)ctx;
    const int64_t r = score(f, u, v, s);
    if (top->n == TOP_K && r >= top->c[TOP_K - 1U].r_q54) {
        return;
    }
    size_t i = (top->n < TOP_K) ? top->n++ : TOP_K - 1U;
    while (i > 0U && top->c[i - 1U].r_q54 > r) {
        top->c[i] = top->c[i - 1U];
        --i;
    }
    top->c[i].r_q54 = r;
    top->c[i].start = start;
    top->c[i].len = len;
}

// Exact least squares for one reading of the fold, from the measurements: t, Q24.
static void solve_exact(const fit_ctx_t *f, uint64_t choice, int32_t *tx, int32_t *ty)
{
    int64_t U = 0; // Q43
    int64_t V = 0;
    for (size_t k = 0; k < f->n; ++k) {
        const sl_tilt_obs_t *o = &f->obs[k];
        const int64_t w = weight_q16(f, k);
        const int64_t t = ((choice >> k) & 1U) != 0U ? o->tan_mirror_q12 : o->tan_q12;
        U += w * o->cos_a_q15 * t;
        V += w * o->sin_a_q15 * t;
    }
    solve_t(f, div_round(U, f->w_sum_q16 * 8), div_round(V, f->w_sum_q16 * 8), tx, ty);
}

typedef struct alt_search {
    int64_t best_r_q54;
    int64_t window_q54;    // consider candidates up to best + this
    int32_t tx_q24;        // the best solution
    int32_t ty_q24;
    int64_t distinct_q24;  // |t - t_best| above this is a different answer
    int64_t alt_r_q54;     // best score among different answers in the window
    size_t alt_start;      // ... its interval
    size_t alt_len;
    bool found;
} alt_search_t;

static void visit_alt(const fit_ctx_t *f, void *ctx, size_t start, size_t len, int64_t u,
                      int64_t v, int64_t s)
{
    alt_search_t *a = (alt_search_t *)ctx;
    const int64_t r = score(f, u, v, s);
    if (r - a->best_r_q54 > a->window_q54 || (a->found && r >= a->alt_r_q54)) {
        return;
    }
    int32_t tx;
    int32_t ty;
    solve_t(f, u, v, &tx, &ty);
    const int64_t dx = (int64_t)tx - a->tx_q24;
    const int64_t dy = (int64_t)ty - a->ty_q24;
    if (dx * dx + dy * dy > a->distinct_q24 * a->distinct_q24) {
        a->alt_r_q54 = r;
        a->alt_start = start;
        a->alt_len = len;
        a->found = true;
    }
}

static uint32_t chi2_direct_q8(const fit_ctx_t *f, uint64_t choice, int32_t tx, int32_t ty)
{
    uint64_t sum_q16 = 0;
    for (size_t k = 0; k < f->n; ++k) {
        const sl_tilt_obs_t *o = &f->obs[k];
        const int64_t t = ((choice >> k) & 1U) != 0U ? o->tan_mirror_q12 : o->tan_q12;
        const int64_t r = t - predict_q12(o, tx, ty);            // Q12
        const int64_t z = div_round(r * 4096, (int64_t)obs_sigma(o)); // Q8
        sum_q16 += (uint64_t)(z * z);
    }
    const uint64_t q8 = sum_q16 >> 8;
    return (q8 > UINT32_MAX) ? UINT32_MAX : (uint32_t)q8;
}

// chi2 from a score: W (r / det) / sigma_min^2, Q8.
static uint32_t chi2_of_score_q8(const fit_ctx_t *f, int64_t r_q54)
{
    if (r_q54 <= 0) {
        return 0U;
    }
    const int64_t q_q24 = div_round(r_q54, f->det_q30);
    const uint64_t sig2_q32 = (uint64_t)f->sigma_min_q16 * f->sigma_min_q16;
    const uint64_t c = ((uint64_t)q_q24 * (uint64_t)f->w_sum_q16) / sig2_q32;
    return (c > UINT32_MAX) ? UINT32_MAX : (uint32_t)c;
}

// t^2 at the normal's 3-sigma point (one-sided tail 0.00135) of Student's t with dof degrees
// of freedom, Q8, dof = SL_TILT_MIN_OBS - 2 .. SL_TILT_MAX_OBS - 2 (9 = 2304 as dof grows):
//   python3 -c "import mpmath as m; m.mp.dps=40; p=m.ncdf(3)
//     f=lambda t,v: m.betainc(v/2.,.5,0,v/(v+t*t),regularized=True)/2-(1-p)
//     print([int(m.nint(m.findroot(lambda t: f(t,v),(1,300),solver='bisect')**2*256))
//            for v in range(3,31)])"
#if SL_TILT_MIN_OBS != 5U || SL_TILT_MAX_OBS != 32U
#error "t2_3sigma_q8 covers dof 3..30: regenerate it for SL_TILT_MIN_OBS .. SL_TILT_MAX_OBS"
#endif
#define T2_DOF_MIN (SL_TILT_MIN_OBS - 2U)
static const uint16_t t2_3sigma_q8[SL_TILT_MAX_OBS - SL_TILT_MIN_OBS + 1U] = {
    21757, 11220, 7764, 6157, 5253, 4682, 4291, 4008, 3794, 3627,
    3494, 3384, 3293, 3216, 3149, 3092, 3042, 2998, 2959, 2924,
    2892, 2864, 2838, 2815, 2793, 2773, 2755, 2738,
};

static uint64_t max_u64(uint64_t a, uint64_t b)
{
    return (a > b) ? a : b;
}

#define CDEG_PER_RAD_Q16 375493621LL // 18000 / pi * 2^16

// Radians (Q30, >= 0) -> 0.01 deg, rounded, saturated to `max`.
static uint16_t rad_q30_to_cdeg(int64_t rad_q30, uint16_t max)
{
    if (rad_q30 >= P2_32) {
        return max;
    }
    const int64_t cdeg = sl_fx_rshift_round64(rad_q30 * CDEG_PER_RAD_Q16, 46U);
    return (cdeg > (int64_t)max) ? max : (uint16_t)cdeg;
}

// p' adj(M) p / det (p a unit vector, Q30): the variance factor along p, Q20.
static int64_t var_factor_q20(const fit_ctx_t *f, sl_q30_t p1, sl_q30_t p2)
{
    const int64_t p11 = sl_fx_mul_q30(p1, p1);
    const int64_t p12 = sl_fx_mul_q30(p1, p2);
    const int64_t p22 = sl_fx_mul_q30(p2, p2);
    const int64_t q_q60 = (int64_t)f->c_q30 * p11 - 2 * (int64_t)f->b_q30 * p12 +
                          (int64_t)f->a_q30 * p22;
    return div_round(q_q60 >> 10, f->det_q30); // Q50 / Q30
}

// The bias bound along p (a unit vector, Q30), tan units, Q30, saturated at 2.0. The errors
// of the measurements are not independent from one rotation to the next (quantised bounds,
// the union extent, the azimuth cells drift slowly along a pass), so they do not average out
// as 1 / sqrt(n): a bias beta_k with |beta_k| <= sigma_k on every measurement, shaped in
// any way over the pass (a trend in bearing is the worst for few, close bearings), moves the
// fit by d t = -M^-1 sum(w_k e_k beta_k) / W, at most
//     b_p = sum(w_k sigma_k |p' M^-1 e_k|) / W
// along p. It does not shrink with n, only with the bearing spread (M^-1 ~ 1 / spread).
static int64_t bias_bound_q30(const fit_ctx_t *f, sl_q30_t p1, sl_q30_t p2)
{
    // g = adj(M) p (adj(M) is symmetric), Q30; then p' adj(M) e_k = g . e_k
    const int64_t g1 = sl_fx_mul_q30(f->c_q30, p1) - sl_fx_mul_q30(f->b_q30, p2);
    const int64_t g2 = sl_fx_mul_q30(f->a_q30, p2) - sl_fx_mul_q30(f->b_q30, p1);
    int64_t sum_q46 = 0;
    for (size_t k = 0; k < f->n; ++k) {
        const sl_tilt_obs_t *o = &f->obs[k];
        int64_t q = (g1 * o->cos_a_q15 + g2 * o->sin_a_q15) >> 15; // Q30, |.| <= 2
        q = (q < 0) ? -q : q;
        sum_q46 += ((weight_q16(f, k) * (int64_t)obs_sigma(o)) >> 16) * q;
    }
    const int64_t mean_q30 = div_round(sum_q46, f->w_sum_q16); // sum(w sigma |adj e|) / W
    if (mean_q30 >= 2 * f->det_q30) {
        return 2 * P2_30;
    }
    return div_round(mean_q30 * P2_30, f->det_q30);
}

// The reading's base: each measurement's point at radar height, averaged, minus H t.
static void reading_base(const fit_ctx_t *f, const sl_tilt_params_t *prm, sl_tilt_reading_t *out)
{
    const int32_t tx32 = out->tx_q24;
    const int32_t ty32 = out->ty_q24;
    const int64_t tanb_q12 = div_round((int64_t)prm->sin_beta_q30 * 4096, prm->cos_beta_q30);
    int64_t sx = 0;
    int64_t sy = 0;
    for (size_t k = 0; k < f->n; ++k) {
        const sl_tilt_obs_t *o = &f->obs[k];
        const int64_t p = predict_q12(o, tx32, ty32); // fitted tan(alpha), Q12
        int64_t d0_um;
        if (p >= tanb_q12) {
            // r1 on the +beta ray: d0 = r1 (cos b + sin b tan alpha)
            const int64_t f_q30 = prm->cos_beta_q30 +
                                  sl_fx_rshift_round64((int64_t)prm->sin_beta_q30 * p, 12U);
            d0_um = sl_fx_rshift_round64((int64_t)o->r1_um * f_q30, 30U);
        } else {
            // r1 is the perpendicular foot: d0 = r1 / cos alpha = r1 sqrt(1 + tan^2)
            const uint64_t sec_q12 = sl_fx_isqrt64(((uint64_t)1 << 24) + (uint64_t)(p * p));
            d0_um = sl_fx_rshift_round64((int64_t)o->r1_um * (int64_t)sec_q12, 12U);
        }
        sx += (int64_t)o->radar_x_um + sl_fx_rshift_round64(d0_um * o->cos_a_q15, 15U);
        sy += (int64_t)o->radar_y_um + sl_fx_rshift_round64(d0_um * o->sin_a_q15, 15U);
    }
    const int64_t n = f->n > 0U ? (int64_t)f->n : 1; // sl_tilt_fit's gate keeps n >= 3
    const int64_t h = (int64_t)prm->radar_height_um;
    out->base_x_um = sl_fx_sat32(div_round(sx, n) - sl_fx_rshift_round64(h * tx32, 24U));
    out->base_y_um = sl_fx_sat32(div_round(sy, n) - sl_fx_rshift_round64(h * ty32, 24U));
}

// One reading: tilt, direction, their sigmas and the base of the tilt vector (tx32, ty32)
// whose chi-square is chi2_q8.
static void reading_of(const fit_ctx_t *f, const sl_tilt_params_t *prm, int32_t tx32,
                       int32_t ty32, uint32_t chi2_q8, sl_tilt_reading_t *out)
{
    SL_ASSERT(f->n >= SL_TILT_MIN_OBS); // sl_tilt_fit's gate: dof = n - 2 > 0, mean over n
    out->tx_q24 = tx32;
    out->ty_q24 = ty32;

    // Tilt and direction.
    const int64_t tx = tx32;
    const int64_t ty = ty32;
    const uint32_t tn_q24 = sl_fx_isqrt64((uint64_t)(tx * tx + ty * ty)); // |t|, Q24
    out->psi_cdeg = sl_incline_bam32_to_cdeg(
        sl_incline_atan2_bam32((int32_t)tn_q24, (int32_t)P2_24));
    int32_t phi = sl_incline_bam32_to_cdeg(sl_incline_atan2_bam32(ty32, tx32));
    if (phi < 0) {
        phi += 36000;
    }
    out->phi_cdeg = (phi >= 36000) ? phi - 36000 : phi;

    // Covariance of t = sigma_min^2 / W * M^-1, inflated by chi2/dof when above 1.
    const uint32_t dof = (uint32_t)f->n - 2U;
    uint64_t inflate_q8 = (uint64_t)chi2_q8 / dof;
    if (inflate_q8 < 256U) {
        inflate_q8 = 256U;
    }
    uint64_t k_q40 = ((uint64_t)f->sigma_min_q16 * f->sigma_min_q16 << 24) /
                     (uint64_t)f->w_sum_q16;
    if (k_q40 > ((uint64_t)1 << 33)) {
        k_q40 = (uint64_t)1 << 33;
    }
    sl_q30_t u1 = SL_Q30_ONE;
    sl_q30_t u2 = 0;
    if (tn_q24 != 0U) {
        u1 = sl_fx_sat32(div_round(tx * P2_30, (int64_t)tn_q24));
        u2 = sl_fx_sat32(div_round(ty * P2_30, (int64_t)tn_q24));
    }
    int64_t sig_q30[2];
    const sl_q30_t dir[2][2] = {{u1, u2}, {(sl_q30_t)-u2, u1}}; // along t, across t
    for (unsigned i = 0; i < 2U; ++i) {
        int64_t f_q20 = var_factor_q20(f, dir[i][0], dir[i][1]);
        if (f_q20 > P2_29) {
            f_q20 = P2_29;
        }
        if (f_q20 < 0) {
            f_q20 = 0;
        }
        uint64_t var_q30 = ((uint64_t)f_q20 * k_q40) >> 30; // Q20 * Q40 -> Q30
        var_q30 = (var_q30 * inflate_q8) >> 8;
        if (var_q30 > ((uint64_t)1 << 32)) {
            var_q30 = (uint64_t)1 << 32;
        }
        // plus the bias bound, as a systematic term (sl_tilt.h, "The stated sigmas")
        const int64_t b_q30 = bias_bound_q30(f, dir[i][0], dir[i][1]); // <= 2^31
        var_q30 += (uint64_t)((b_q30 * b_q30) >> 30);
        if (var_q30 > ((uint64_t)1 << 32)) {
            var_q30 = (uint64_t)1 << 32;
        }
        sig_q30[i] = (int64_t)sl_fx_isqrt64(var_q30 << 30);
    }
    // d psi = d|t| / (1 + |t|^2); d phi = d(across) / |t|: linearisations that hold only when
    // |t| is well above its error in every direction. When it is not (|t| < 3 x the larger
    // sigma), the direction is not determined (phi sigma saturated) and |t| may be off by the
    // error across t as much as along it (a small fitted |t| can hide a tilt across it).
    const int64_t sec2_q24 = P2_24 + (int64_t)(((uint64_t)tn_q24 * tn_q24) >> 24);
    const int64_t sig_max_q30 = (sig_q30[1] > sig_q30[0]) ? sig_q30[1] : sig_q30[0];
    const bool oriented = (int64_t)tn_q24 * 64 >= 3 * sig_max_q30; // Q24 -> Q30
    const int64_t sig_psi_q30 = oriented ? sig_q30[0] : sig_max_q30;
    out->psi_sigma_cdeg = rad_q30_to_cdeg(div_round(sig_psi_q30 << 24, sec2_q24), UINT16_MAX);
    out->phi_sigma_cdeg = (!oriented || tn_q24 == 0U) ? 18000U
        : rad_q30_to_cdeg(div_round(sig_q30[1] << 24, (int64_t)tn_q24), 18000U);
    reading_base(f, prm, out);
}


static void report(const fit_ctx_t *f, const sl_tilt_params_t *prm, uint64_t choice, int32_t tx32,
                   int32_t ty32, uint32_t chi2_q8, sl_tilt_result_t *out)
{
    out->chi2_q8 = chi2_q8;
    unsigned mirrored = 0U;
    for (size_t k = 0; k < f->n; ++k) {
        mirrored += (unsigned)((choice >> k) & 1U);
    }
    out->n_mirrored = (uint8_t)mirrored;
    out->mirrored_mask = (uint32_t)choice;
    sl_tilt_reading_t rd;
    reading_of(f, prm, tx32, ty32, chi2_q8, &rd);
    out->tx_q24 = rd.tx_q24;
    out->ty_q24 = rd.ty_q24;
    out->psi_cdeg = rd.psi_cdeg;
    out->phi_cdeg = rd.phi_cdeg;
    out->psi_sigma_cdeg = rd.psi_sigma_cdeg;
    out->phi_sigma_cdeg = rd.phi_sigma_cdeg;
    out->base_x_um = rd.base_x_um;
    out->base_y_um = rd.base_y_um;
}

// The fold reading of candidate interval (start, len) in bearing order: bit k set =
// measurement k read as its mirror.
static uint64_t interval_choice(const fit_ctx_t *f, size_t start, size_t len)
{
    uint64_t ch = 0U;
    for (size_t j = 0; j < len; ++j) {
        const size_t idx = start + j;
        ch |= (uint64_t)1U << f->wk->order[(idx >= f->m) ? idx - f->m : idx];
    }
    return ch;
}

// Bearing of a measurement relative to `ref` (signed bam32).
static int32_t rel_bearing(const sl_tilt_obs_t *o, sl_bam32_t ref)
{
    return (int32_t)(sl_incline_atan2_bam32(o->sin_a_q15, o->cos_a_q15) - ref);
}

// The weights (sigma_min / sigma_k)^2 and the moments that do not depend on the fold:
// the normalised bearing moments and their determinant, (u, v, s) as measured. False when
// the bearings do not spread (SL_TILT_INSUFFICIENT_MOTION).
static bool fit_moments(fit_ctx_t *f)
{
    uint16_t smin = UINT16_MAX;
    for (size_t k = 0; k < f->n; ++k) {
        const uint16_t s = obs_sigma(&f->obs[k]);
        smin = (s < smin) ? s : smin;
    }
    f->sigma_min_q16 = smin;
    int64_t A = 0; // Q46
    int64_t B = 0;
    int64_t C = 0;
    int64_t U = 0; // Q43
    int64_t V = 0;
    int64_t S = 0; // Q40
    for (size_t k = 0; k < f->n; ++k) {
        const int64_t w = weight_q16(f, k);
        f->w_sum_q16 += w;
        const int64_t c = f->obs[k].cos_a_q15;
        const int64_t s = f->obs[k].sin_a_q15;
        const int64_t t = f->obs[k].tan_q12;
        A += (int64_t)w * c * c;
        B += (int64_t)w * c * s;
        C += (int64_t)w * s * s;
        U += (int64_t)w * c * t;
        V += (int64_t)w * s * t;
        S += (int64_t)w * t * t;
    }
    const int64_t W = f->w_sum_q16;
    f->a_q30 = sl_fx_sat32(div_round(A, W));
    f->b_q30 = sl_fx_sat32(div_round(B, W));
    f->c_q30 = sl_fx_sat32(div_round(C, W));
    f->det_q30 = sl_fx_rshift_round64((int64_t)f->a_q30 * f->c_q30 - (int64_t)f->b_q30 * f->b_q30, 30U);
    if (f->det_q30 < SL_TILT_MIN_SPREAD_Q30) {
        return false;
    }
    f->u0_q24 = div_round(U, W * 8);
    f->v0_q24 = div_round(V, W * 8);
    f->s0_q24 = div_round(S, W);
    return true;
}

// Mirrorable measurements in bearing order (around their mean direction), with the change
// each makes to (u, v, s) when read as the mirror.
static void fit_fold_order(fit_ctx_t *f)
{
    sl_tilt_work_t *wk = f->wk;
    const sl_tilt_obs_t *obs = f->obs;
    const int64_t W = f->w_sum_q16;
    int64_t mc = 0;
    int64_t ms = 0;
    size_t m = 0;
    for (size_t k = 0; k < f->n; ++k) {
        if (obs[k].mirrorable != 0U) {
            mc += obs[k].cos_a_q15;
            ms += obs[k].sin_a_q15;
            wk->order[m++] = (uint8_t)k;
        }
    }
    f->m = m;
    const sl_bam32_t ref = sl_incline_atan2_bam32(sl_fx_sat32(ms), sl_fx_sat32(mc));
    for (size_t i = 1; i < m; ++i) { // insertion sort, m <= 32
        const uint8_t key = wk->order[i];
        const int32_t kb = rel_bearing(&obs[key], ref);
        size_t j = i;
        while (j > 0U && rel_bearing(&obs[wk->order[j - 1U]], ref) > kb) {
            wk->order[j] = wk->order[j - 1U];
            --j;
        }
        wk->order[j] = key;
    }
    for (size_t j = 0; j < m; ++j) {
        const sl_tilt_obs_t *o = &obs[wk->order[j]];
        const int64_t w = weight_q16(f, wk->order[j]);
        const int64_t t0 = o->tan_q12;
        const int64_t t1 = o->tan_mirror_q12;
        wk->du_q24[j] = sl_fx_sat32(div_round(w * o->cos_a_q15 * (t1 - t0), W * 8));
        wk->dv_q24[j] = sl_fx_sat32(div_round(w * o->sin_a_q15 * (t1 - t0), W * 8));
        wk->ds_q24[j] = sl_fx_sat32(div_round(w * (t1 * t1 - t0 * t0), W));
    }
}

// The best reading of the fold: the TOP_K intervals by score, then the best of them by
// exact chi-square. Returns the best score (for the ambiguity window).
typedef struct best_fit {
    uint64_t choice;
    int32_t tx_q24;
    int32_t ty_q24;
    uint32_t chi2_q8;
} best_fit_t;

static SL_NOINLINE int64_t fit_best(const fit_ctx_t *f, best_fit_t *b)
{
    top_k_t top;
    memset(&top, 0, sizeof top);
    enumerate(f, visit_best, &top);
    b->chi2_q8 = UINT32_MAX;
    int64_t best_r = INT64_MAX;
    for (size_t c = 0; c < top.n; ++c) {
        const uint64_t ch = interval_choice(f, top.c[c].start, top.c[c].len);
        int32_t cx;
        int32_t cy;
        solve_exact(f, ch, &cx, &cy);
        const uint32_t x2 = chi2_direct_q8(f, ch, cx, cy);
        if (c == 0U || x2 < b->chi2_q8) {
            b->chi2_q8 = x2;
            b->choice = ch;
            b->tx_q24 = cx;
            b->ty_q24 = cy;
        }
        best_r = (top.c[c].r_q54 < best_r) ? top.c[c].r_q54 : best_r;
    }
    return best_r;
}

// The ambiguity margin, chi-square units (Q8). The stated sigmas are a floor, not the whole
// error: quantised bounds, the union extent and the azimuth cells add errors that are neither
// Gaussian nor independent from one rotation to the next. So the scale of the chi-square is
// estimated from the best fit's residuals, s^2 = max(1, chi2 / dof) (the same inflation
// reading_of() applies to the sigmas), and with a scale estimated from dof residuals the
// 3-sigma test of the difference is Student's t with dof degrees of freedom, not the
// normal's 9: margin = t^2 s^2 (sl_tilt.h).
static uint64_t ambiguity_margin_q8(uint32_t chi2_q8, uint32_t dof)
{
    uint64_t s2_q8 = (uint64_t)chi2_q8 / dof;
    s2_q8 = (s2_q8 < 256U) ? 256U : s2_q8;
    const uint64_t margin_q8 = ((uint64_t)t2_3sigma_q8[dof - T2_DOF_MIN] * s2_q8) >> 8;
    return (margin_q8 > UINT32_MAX) ? UINT32_MAX : margin_q8;
}

// Pass 2: the best candidate with a different answer than `b`, within a window of scores
// that covers the margin (and at least 16 x the normal's 9, so chi2_other says how far the
// nearest other reading is).
static SL_NOINLINE void fit_other(const fit_ctx_t *f, const best_fit_t *b, int64_t best_r,
                                  uint64_t margin_q8, alt_search_t *alt)
{
    memset(alt, 0, sizeof *alt);
    alt->best_r_q54 = best_r;
    // margin in score units: d chi2 = W d(r / det) / sigma_min^2 -> d r = chi2 sigma^2 det / W
    const uint64_t sig2 = (uint64_t)f->sigma_min_q16 * f->sigma_min_q16; // Q32
    const int64_t per_chi2_q46 = (int64_t)((sig2 * (uint64_t)f->det_q30) / (uint64_t)f->w_sum_q16);
    const uint64_t window_q8 = max_u64(margin_q8, (uint64_t)16 * (uint64_t)SL_TILT_AMBIGUITY_CHI2_Q8);
    alt->window_q54 = (per_chi2_q46 > 0 && window_q8 > (uint64_t)INT64_MAX / (uint64_t)per_chi2_q46)
                          ? INT64_MAX
                          : per_chi2_q46 * (int64_t)window_q8;
    alt->tx_q24 = b->tx_q24;
    alt->ty_q24 = b->ty_q24;
    const int64_t tx = b->tx_q24;
    const int64_t ty = b->ty_q24;
    const int64_t tn = (int64_t)sl_fx_isqrt64((uint64_t)(tx * tx + ty * ty));
    const int64_t d_min = P2_24 * 35 / 1000; // 0.035 (2 deg)
    const int64_t d_rel = tn * 3 / 10;
    alt->distinct_q24 = (d_rel > d_min) ? d_rel : d_min;
    if (f->m > 0U) {
        enumerate(f, visit_alt, alt);
    }
}

sl_err_t sl_tilt_fit(const sl_tilt_obs_t *obs, size_t n, const sl_tilt_params_t *prm,
                     sl_tilt_work_t *work, sl_tilt_result_t *out)
{
    if (out == NULL) {
        return SL_ERR_ARG;
    }
    memset(out, 0, sizeof *out);
    if (obs == NULL || prm == NULL || work == NULL || n > SL_TILT_MAX_OBS ||
        prm->cos_beta_q30 <= 0) {
        return SL_ERR_ARG;
    }
    out->n_obs = (uint8_t)n;
    if (n < SL_TILT_MIN_OBS) {
        out->quality = (uint8_t)SL_TILT_TOO_FEW;
        return SL_OK;
    }
    fit_ctx_t f;
    memset(&f, 0, sizeof f);
    f.obs = obs;
    f.n = n;
    f.wk = work;
    if (!fit_moments(&f)) {
        out->quality = (uint8_t)SL_TILT_INSUFFICIENT_MOTION;
        return SL_OK;
    }
    fit_fold_order(&f);
    best_fit_t b;
    const int64_t best_r = fit_best(&f, &b);
    const uint32_t dof = (uint32_t)n - 2U;
    const uint64_t margin_q8 = ambiguity_margin_q8(b.chi2_q8, dof);
    alt_search_t alt;
    fit_other(&f, &b, best_r, margin_q8, &alt);
    out->chi2_other_q8 = alt.found ? chi2_of_score_q8(&f, alt.alt_r_q54) : UINT32_MAX;

    report(&f, prm, b.choice, b.tx_q24, b.ty_q24, b.chi2_q8, out);
    const uint32_t best_chi2_fast = chi2_of_score_q8(&f, best_r);
    const bool ambiguous = alt.found &&
        ((uint64_t)out->chi2_other_q8 < (uint64_t)best_chi2_fast + margin_q8);
    if ((uint64_t)b.chi2_q8 > (uint64_t)SL_TILT_INCONSISTENT_CHI2_Q8 * dof) {
        // Not a straight pole seen as measured (whatever reading of the fold): its scale
        // estimate would call every reading ambiguous, and that is not what is wrong.
        out->quality = (uint8_t)SL_TILT_INCONSISTENT;
    } else if (ambiguous) {
        // Both readings: the other one solved exactly from the measurements, as the best.
        out->quality = (uint8_t)SL_TILT_AMBIGUOUS;
        const uint64_t ch = interval_choice(&f, alt.alt_start, alt.alt_len);
        int32_t cx;
        int32_t cy;
        solve_exact(&f, ch, &cx, &cy);
        reading_of(&f, prm, cx, cy, chi2_direct_q8(&f, ch, cx, cy), &out->mirror);
        out->mirror_mask = (uint32_t)ch;
    } else {
        out->quality = (uint8_t)SL_TILT_FITTED;
    }
    return SL_OK;
}

// ---------------------------------------------------------------------------------------
// Odometry.

#define BAM_PER_MDEG_US_Q24 200160LL // 2^32 / 360 / 1e9 * 2^24
#define ODOM_DT_MAX_US 1000000U
#define ODOM_SPEED_MAX_MM_S 100000
#define ODOM_RATE_MAX_MDEG_S 720000

void sl_tilt_odom_step(sl_tilt_odom_t *o, int32_t speed_mm_s, int32_t yaw_rate_mdeg_s,
                       uint32_t dt_us)
{
    if (o == NULL) {
        return;
    }
    const uint32_t dt = (dt_us > ODOM_DT_MAX_US) ? ODOM_DT_MAX_US : dt_us;
    const int32_t v = (speed_mm_s > ODOM_SPEED_MAX_MM_S) ? ODOM_SPEED_MAX_MM_S
                      : (speed_mm_s < -ODOM_SPEED_MAX_MM_S) ? -ODOM_SPEED_MAX_MM_S : speed_mm_s;
    const int32_t w = (yaw_rate_mdeg_s > ODOM_RATE_MAX_MDEG_S) ? ODOM_RATE_MAX_MDEG_S
                      : (yaw_rate_mdeg_s < -ODOM_RATE_MAX_MDEG_S) ? -ODOM_RATE_MAX_MDEG_S
                                                                  : yaw_rate_mdeg_s;
    const int64_t dyaw = sl_fx_rshift_round64((int64_t)w * (int64_t)dt * BAM_PER_MDEG_US_Q24, 24U);
    const sl_bam32_t mid = o->yaw + (sl_bam32_t)(int32_t)(dyaw / 2);
    sl_q30_t s;
    sl_q30_t c;
    sl_tilt_sincos_q30(mid, &s, &c);
    const int64_t dist_um = div_round((int64_t)v * (int64_t)dt, 1000);
    o->x_um += sl_fx_rshift_round64(dist_um * c, 30U);
    o->y_um += sl_fx_rshift_round64(dist_um * s, 30U);
    o->yaw += (sl_bam32_t)(int32_t)dyaw;
}
