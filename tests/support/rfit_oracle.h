// SPDX-License-Identifier: MIT
// rfit_oracle.h: the forward model of sl_rfit.h in double precision, and its maximum-
// likelihood fit by a direct search (Nelder-Mead over the bounds, the level by Newton's
// method), with the Fisher covariance at the optimum. The oracle of the fixed-point fit
// (test_rfit.c) and of the host tools. The FOOT density is integrated exactly (fine equal-mass
// steps), not by the core's equal-mass pieces. Tests and host tools only, never the core.
#ifndef SL_TEST_RFIT_ORACLE_H
#define SL_TEST_RFIT_ORACLE_H

#include <math.h>
#include <stdlib.h>
#include <stdint.h>
#include <string.h>

#include "shadowlean/sl_response.h"
#include "shadowlean/sl_rfit.h"

typedef struct sl_ro_resp {
    double tap[SL_RESP_TAPS]; // linear, centre 1
    double area;              // integral, bins
    double ncorr;             // (sum tap)^2 / sum tap^2
    double rho2[SL_RESP_TAPS]; // correlation of speckled powers Delta bins apart
} sl_ro_resp_t;

static inline void sl_ro_resp_from_drops(const uint16_t *drop_q8, sl_ro_resp_t *r)
{
    double s1 = 0, s2 = 0;
    for (int i = 0; i < SL_RESP_TAPS; i++) {
        r->tap[i] = pow(2.0, -drop_q8[i] / 256.0);
        s1 += r->tap[i];
        s2 += r->tap[i] * r->tap[i];
    }
    r->area = s1; // the piecewise-linear integral of taps that end at zero beyond the table
    r->area -= 0.5 * (r->tap[0] + r->tap[SL_RESP_TAPS - 1]);
    r->ncorr = s1 * s1 / s2;
    double c0 = 0;
    for (int i = 0; i < SL_RESP_TAPS; i++) c0 += r->tap[i];
    for (int d = 0; d < SL_RESP_TAPS; d++) {
        double cd = 0;
        for (int i = 0; i + d < SL_RESP_TAPS; i++) cd += sqrt(r->tap[i] * r->tap[i + d]);
        r->rho2[d] = (cd / c0) * (cd / c0);
    }
}

// Linear response at offset x (bins), 0 outside the taps.
static inline double sl_ro_at(const sl_ro_resp_t *r, double x)
{
    const double u = x + SL_CFG_RESP_HALF;
    if (u < 0 || u > SL_RESP_TAPS - 1) return 0.0;
    const int i = (int)floor(u);
    if (i >= SL_RESP_TAPS - 1) return r->tap[SL_RESP_TAPS - 1];
    const double t = u - i;
    return r->tap[i] * (1 - t) + r->tap[i + 1] * t;
}

// Integral of the response over [x0, x1] (exact for the piecewise-linear response, by
// Simpson's rule on each linear piece's sub-interval).
static inline double sl_ro_int(const sl_ro_resp_t *r, double x0, double x1)
{
    if (x0 < -SL_CFG_RESP_HALF) x0 = -SL_CFG_RESP_HALF; // the response is 0 beyond its taps
    if (x1 > SL_CFG_RESP_HALF) x1 = SL_CFG_RESP_HALF;
    if (x1 <= x0) return 0.0;
    double acc = 0;
    double x = x0;
    while (x < x1) {
        double nx = floor(x + SL_CFG_RESP_HALF) + 1 - SL_CFG_RESP_HALF; // next tap
        while (nx <= x + 1e-12) nx += 1.0; // x on a tap, up to rounding
        if (nx > x1) nx = x1;
        acc += (nx - x) * 0.5 * (sl_ro_at(r, x) + sl_ro_at(r, nx));
        x = nx;
    }
    return acc;
}

#define SL_RO_STEPS 256

// Model m_k (fraction of the return's power in sample k), k < n.
static inline void sl_ro_model(const sl_ro_resp_t *r, int shape, double origin, double a,
                               double b, int n, double *m)
{
    for (int k = 0; k < n; k++) m[k] = 0;
    if (b <= a) b = a + 1e-6;
    if (shape == SL_RFIT_UNIFORM) {
        for (int k = 0; k < n; k++) m[k] = sl_ro_int(r, k - b, k - a) / (b - a) / r->area;
        return;
    }
    const double a0 = origin + a, b0 = origin + b;
    const double m2 = b0 * b0 - a0 * a0;
    double xp = a;
    for (int s = 1; s <= SL_RO_STEPS; s++) {
        const double q = (double)s / SL_RO_STEPS;
        const double xn = sqrt(a0 * a0 + q * q * m2) - origin;
        const double w = xn - xp;
        for (int k = 0; k < n; k++) {
            const double in = (w > 1e-12) ? sl_ro_int(r, k - xn, k - xp) / w
                                          : sl_ro_at(r, k - xp);
            m[k] += in / SL_RO_STEPS / r->area;
        }
        xp = xn;
    }
}

typedef struct sl_ro_fit {
    double a, b, level, nll;
    double sigma_a, sigma_b, corr;
} sl_ro_fit_t;

typedef struct sl_ro_prob {
    const sl_ro_resp_t *r;
    const double *y, *f;
    int n, shape;
    double origin, w;
} sl_ro_prob_t;

static inline double sl_ro_nll_ab(const sl_ro_prob_t *p, double a, double b, double *level_io)
{
    double m[SL_RFIT_MAX_N];
    sl_ro_model(p->r, p->shape, p->origin, a, b, p->n, m);
    double l = log(*level_io > 1e-300 ? *level_io : 1e-300);
    for (int it = 0; it < 40; it++) { // Newton on ln level
        double g = 0, h = 0;
        const double A = exp(l);
        for (int k = 0; k < p->n; k++) {
            const double mu = p->f[k] + A * m[k];
            const double d = A * m[k];
            g += d * (1.0 / mu - p->y[k] / (mu * mu));
            h += d * d / (mu * mu);
        }
        if (h <= 0) break;
        double step = g / h;
        if (step > 2) step = 2;
        if (step < -2) step = -2;
        l -= step;
        if (fabs(step) < 1e-10) break;
    }
    *level_io = exp(l);
    double J = 0;
    for (int k = 0; k < p->n; k++) {
        const double mu = p->f[k] + *level_io * m[k];
        J += log(mu) + p->y[k] / mu;
    }
    return p->w * J;
}

// The bounds' covariance: the sandwich N^-1 M N^-1 of the independence likelihood (N its
// information, M the score's covariance with the speckle's correlation between bins), for
// (a, b) with the level profiled out; per look, divided by the looks.
static inline void sl_ro_cov(const sl_ro_prob_t *p, sl_ro_fit_t *f)
{
    double m0[SL_RFIT_MAX_N], ma[SL_RFIT_MAX_N], mb[SL_RFIT_MAX_N], mc[SL_RFIT_MAX_N],
        md[SL_RFIT_MAX_N], j[SL_RFIT_MAX_N][3];
    const double h = 1e-3;
    sl_ro_model(p->r, p->shape, p->origin, f->a, f->b, p->n, m0);
    sl_ro_model(p->r, p->shape, p->origin, f->a + h, f->b, p->n, ma);
    sl_ro_model(p->r, p->shape, p->origin, f->a - h, f->b, p->n, mc);
    sl_ro_model(p->r, p->shape, p->origin, f->a, f->b + h, p->n, mb);
    sl_ro_model(p->r, p->shape, p->origin, f->a, f->b - h, p->n, md);
    double N[3][3] = {{0}};
    for (int k = 0; k < p->n; k++) {
        const double mu = p->f[k] + f->level * m0[k];
        j[k][0] = f->level * m0[k] / mu;
        j[k][1] = f->level * (ma[k] - mc[k]) / (2 * h) / mu;
        j[k][2] = f->level * (mb[k] - md[k]) / (2 * h) / mu;
        for (int i = 0; i < 3; i++)
            for (int q = 0; q < 3; q++) N[i][q] += j[k][i] * j[k][q];
    }
    // project the level off, then the 2x2 sandwich
    double t[SL_RFIT_MAX_N][2];
    for (int k = 0; k < p->n; k++) {
        t[k][0] = j[k][1] - N[1][0] / N[0][0] * j[k][0];
        t[k][1] = j[k][2] - N[2][0] / N[0][0] * j[k][0];
    }
    double n2[2][2] = {{0}}, m2[2][2] = {{0}};
    for (int k = 0; k < p->n; k++)
        for (int l = 0; l < p->n; l++) {
            const int d = abs(k - l);
            const double w = (d < SL_RESP_TAPS) ? p->r->rho2[d] : 0.0;
            for (int i = 0; i < 2; i++)
                for (int q = 0; q < 2; q++) {
                    if (k == l) n2[i][q] += t[k][i] * t[k][q];
                    m2[i][q] += w * t[k][i] * t[l][q];
                }
        }
    const double det = n2[0][0] * n2[1][1] - n2[0][1] * n2[1][0];
    const double g[2][2] = {{n2[1][1] / det, -n2[0][1] / det}, {-n2[1][0] / det, n2[0][0] / det}};
    double gm[2][2] = {{0}}, c[2][2] = {{0}};
    for (int i = 0; i < 2; i++)
        for (int q = 0; q < 2; q++)
            for (int s2 = 0; s2 < 2; s2++) gm[i][q] += g[i][s2] * m2[s2][q];
    for (int i = 0; i < 2; i++)
        for (int q = 0; q < 2; q++)
            for (int s2 = 0; s2 < 2; s2++) c[i][q] += gm[i][s2] * g[s2][q];
    f->sigma_a = sqrt(c[0][0] / p->w);
    f->sigma_b = sqrt(c[1][1] / p->w);
    f->corr = c[0][1] / sqrt(c[0][0] * c[1][1]);
}

// J at (a, b) with the level profiled out (for comparisons with another fit's point).
static inline double sl_ro_nll_at(const sl_ro_resp_t *r, int shape, double origin,
                                  const double *y, const double *f, int n, double looks,
                                  double a, double b)
{
    sl_ro_prob_t p = {r, y, f, n, shape, origin, looks};
    double tot = 0;
    for (int k = 0; k < n; k++) tot += (y[k] > f[k]) ? y[k] - f[k] : 0;
    double lv = tot > 0 ? tot : 1;
    return sl_ro_nll_ab(&p, a, b, &lv);
}

// Nelder-Mead over (a, b) from (a0, b0), the level profiled out.
static inline sl_ro_fit_t sl_ro_fit(const sl_ro_resp_t *r, int shape, double origin,
                                    const double *y, const double *f, int n, double looks,
                                    double a0, double b0)
{
    sl_ro_prob_t p = {r, y, f, n, shape, origin, looks};
    double s[3][2] = {{a0, b0}, {a0 + 0.5, b0}, {a0, b0 + 0.5}};
    double lv[3] = {0, 0, 0}, v[3];
    double tot = 0;
    for (int k = 0; k < n; k++) tot += (y[k] > f[k]) ? y[k] - f[k] : 0;
    for (int i = 0; i < 3; i++) {
        lv[i] = tot > 0 ? tot : 1;
        if (s[i][1] < s[i][0] + 1e-3) s[i][1] = s[i][0] + 1e-3;
        v[i] = sl_ro_nll_ab(&p, s[i][0], s[i][1], &lv[i]);
    }
    for (int it = 0; it < 400; it++) {
        int hi = 0, lo = 0;
        for (int i = 1; i < 3; i++) {
            if (v[i] > v[hi]) hi = i;
            if (v[i] < v[lo]) lo = i;
        }
        int mid = 3 - hi - lo;
        if (hi == lo) mid = (hi + 1) % 3;
        double c[2] = {0, 0};
        for (int i = 0; i < 3; i++)
            if (i != hi)
                for (int d = 0; d < 2; d++) c[d] += s[i][d] / 2;
        double xr[2] = {2 * c[0] - s[hi][0], 2 * c[1] - s[hi][1]};
        if (xr[1] < xr[0] + 1e-3) xr[1] = xr[0] + 1e-3;
        double lr = lv[lo];
        double vr = sl_ro_nll_ab(&p, xr[0], xr[1], &lr);
        if (vr < v[lo]) {
            double xe[2] = {3 * c[0] - 2 * s[hi][0], 3 * c[1] - 2 * s[hi][1]};
            if (xe[1] < xe[0] + 1e-3) xe[1] = xe[0] + 1e-3;
            double le = lr;
            double ve = sl_ro_nll_ab(&p, xe[0], xe[1], &le);
            if (ve < vr) { memcpy(s[hi], xe, sizeof xe); v[hi] = ve; lv[hi] = le; }
            else { memcpy(s[hi], xr, sizeof xr); v[hi] = vr; lv[hi] = lr; }
        } else if (vr < v[mid]) {
            memcpy(s[hi], xr, sizeof xr); v[hi] = vr; lv[hi] = lr;
        } else {
            double xc[2] = {(c[0] + s[hi][0]) / 2, (c[1] + s[hi][1]) / 2};
            if (xc[1] < xc[0] + 1e-3) xc[1] = xc[0] + 1e-3;
            double lc = lv[hi];
            double vc = sl_ro_nll_ab(&p, xc[0], xc[1], &lc);
            if (vc < v[hi]) { memcpy(s[hi], xc, sizeof xc); v[hi] = vc; lv[hi] = lc; }
            else {
                for (int i = 0; i < 3; i++) {
                    if (i == lo) continue;
                    s[i][0] = (s[i][0] + s[lo][0]) / 2;
                    s[i][1] = (s[i][1] + s[lo][1]) / 2;
                    v[i] = sl_ro_nll_ab(&p, s[i][0], s[i][1], &lv[i]);
                }
            }
        }
        double spread = fabs(s[0][0] - s[1][0]) + fabs(s[0][0] - s[2][0]) +
                        fabs(s[0][1] - s[1][1]) + fabs(s[0][1] - s[2][1]);
        if (spread < 1e-6) break;
    }
    int lo = 0;
    for (int i = 1; i < 3; i++)
        if (v[i] < v[lo]) lo = i;
    sl_ro_fit_t out = {s[lo][0], s[lo][1], lv[lo], v[lo], 0, 0, 0};
    sl_ro_cov(&p, &out);
    return out;
}

#endif // SL_TEST_RFIT_ORACLE_H
