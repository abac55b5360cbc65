// SPDX-License-Identifier: MIT
// calib_file.c: a vehicle's calibration file (INI or blob) -> the core's blob. See calib_file.h.
#include "calib_file.h"

#include <errno.h>
#include <ini.h>
#include <math.h>
#include <stdarg.h>
#include <stdbool.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "geom.h"
#include "shadowlean/sl_calblob.h"

static const double k_pi = 3.14159265358979323846;

typedef struct ctx {
    const sl_board_t *nom;
    char why[256];
    int version;
    double height_m;             // < 0: the board's
    double theta_deg[SL_CFG_MAX_AZIMUTHS];
    bool have[SL_CFG_MAX_AZIMUTHS];
    unsigned measured;
    double theta_sigma_deg;      // < 0: the board's
    double pole_radius_m;        // < 0: the board's
    double near_exclusion_m;     // < 0: the board's
    unsigned elong_n;
    bool elong_set;
    double elong_r[SL_CFG_MAX_ELONG_POINTS];
    double elong_d[SL_CFG_MAX_ELONG_POINTS];
    unsigned resp_n;             // [response] drops_q8 values read (continuation lines add)
    uint16_t resp_q8[SL_RESP_TAPS];
    // the calibrated tables being built (serialised into the blob)
    sl_incline_geom_t geom[SL_CFG_MAX_AZIMUTHS];
    int16_t theta[SL_CFG_MAX_AZIMUTHS];
    uint32_t shadow[SL_CFG_MAX_AZIMUTHS];
    uint16_t bins[SL_CFG_MAX_AZIMUTHS];
} ctx_t;

static int bad(ctx_t *c, const char *fmt, ...)
{
    va_list ap;
    va_start(ap, fmt);
    vsnprintf(c->why, sizeof c->why, fmt, ap);
    va_end(ap);
    return 0;
}

static bool number(const char *s, double *v)
{
    char *end = NULL;
    errno = 0;
    const double d = strtod(s, &end);
    if (end == s || errno != 0 || !isfinite(d)) {
        return false;
    }
    while (*end == ' ' || *end == '\t') {
        end++;
    }
    if (*end != '\0') {
        return false;
    }
    *v = d;
    return true;
}

// Calls fn(c, a, b) for each "a:b" item of a comma-separated list; 0 on error.
static int pairs(ctx_t *c, const char *key, const char *val,
                 int (*fn)(ctx_t *, const char *, double, double))
{
    char buf[512];
    if (strlen(val) >= sizeof buf) {
        return bad(c, "%s: line too long", key);
    }
    strcpy(buf, val);
    char *save = NULL;
    for (char *tok = strtok_r(buf, ",", &save); tok != NULL; tok = strtok_r(NULL, ",", &save)) {
        while (*tok == ' ' || *tok == '\t') {
            tok++;
        }
        if (*tok == '\0') {
            continue; // trailing comma before a continuation line
        }
        char *colon = strchr(tok, ':');
        double a = 0, b = 0;
        if (colon == NULL) {
            return bad(c, "%s: '%s' is not 'a:b'", key, tok);
        }
        *colon = '\0';
        if (!number(tok, &a) || !number(colon + 1, &b)) {
            return bad(c, "%s: '%s:%s' is not two numbers", key, tok, colon + 1);
        }
        if (fn(c, key, a, b) == 0) {
            return 0;
        }
    }
    return 1;
}

static int add_theta(ctx_t *c, const char *key, double az, double deg)
{
    if (az < 0 || floor(az) < az || az >= (double)c->nom->azimuths) {
        return bad(c, "%s: azimuth index %g outside 0..%u", key, az, (unsigned)c->nom->azimuths - 1U);
    }
    if (!(deg >= 1.0 && deg <= 60.0)) {
        return bad(c, "%s: azimuth %g: theta %g deg outside [1, 60]", key, az, deg);
    }
    const size_t i = (size_t)az;
    if (!c->have[i]) {
        c->measured++;
    }
    c->have[i] = true;
    c->theta_deg[i] = deg;
    return 1;
}

static int add_elong(ctx_t *c, const char *key, double r, double d)
{
    if (c->elong_n >= SL_CFG_MAX_ELONG_POINTS) {
        return bad(c, "%s: more than %u points", key, (unsigned)SL_CFG_MAX_ELONG_POINTS);
    }
    if (!(r > 0 && r <= 200.0) || !(fabs(d) <= 5.0)) {
        return bad(c, "%s: '%g:%g' out of range (0..200 m : |d| <= 5 m)", key, r, d);
    }
    if (c->elong_n > 0 && r <= c->elong_r[c->elong_n - 1U]) {
        return bad(c, "%s: ranges must ascend", key);
    }
    c->elong_r[c->elong_n] = r;
    c->elong_d[c->elong_n] = d;
    c->elong_n++;
    return 1;
}

static int scalar(ctx_t *c, const char *key, const char *val, double lo, double hi, double *out)
{
    double v = 0;
    if (!number(val, &v) || v < lo || v > hi) {
        return bad(c, "%s = '%s': expected a number in [%g, %g]", key, val, lo, hi);
    }
    *out = v;
    return 1;
}

// [response] drops_q8: SL_RESP_TAPS integers (comma separated, over continuation lines,
// which inih passes as repeats of the key), the drop below a point return's centre at
// offsets -SL_CFG_RESP_HALF .. +SL_CFG_RESP_HALF, log2 power Q8. Count and shape: build().
static int drops(ctx_t *c, const char *value)
{
    const char *s = value;
    while (*s != '\0') {
        char *end = NULL;
        errno = 0;
        const long v = strtol(s, &end, 10);
        if (end == s || errno != 0 || v < 0 || v > 65535) {
            return bad(c, "drops_q8: '%s' is not a list of integers 0..65535", value);
        }
        if (c->resp_n >= (unsigned)SL_RESP_TAPS) {
            return bad(c, "drops_q8: more than %d values (offsets -%d..+%d)", SL_RESP_TAPS,
                       SL_CFG_RESP_HALF, SL_CFG_RESP_HALF);
        }
        c->resp_q8[c->resp_n++] = (uint16_t)v;
        s = end;
        while (*s == ' ' || *s == '\t' || *s == ',') {
            s++;
        }
    }
    return 1;
}

static int on_entry(void *user, const char *section, const char *name, const char *value)
{
    ctx_t *c = user;
    if (strcmp(section, "calib") == 0) {
        double v = 0;
        if (strcmp(name, "version") == 0) {
            if (scalar(c, name, value, 1, 1, &v) == 0) {
                return bad(c, "version = '%s': this reader knows version 1", value);
            }
            c->version = 1;
            return 1;
        }
        if (strcmp(name, "board") == 0) {
            if (strcmp(value, c->nom->name) != 0) {
                return bad(c, "board = '%s' but the board is '%s'", value, c->nom->name);
            }
            return 1;
        }
        if (strcmp(name, "azimuths") == 0) {
            if (!number(value, &v) || llround(v) != (long long)c->nom->azimuths || floor(v) < v) {
                return bad(c, "azimuths = '%s' but board %s has %u", value, c->nom->name,
                           (unsigned)c->nom->azimuths);
            }
            return 1;
        }
        if (strcmp(name, "radar_height_m") == 0) {
            return scalar(c, name, value, 0.2, 20.0, &c->height_m);
        }
        if (strcmp(name, "theta_sigma_deg") == 0) {
            return scalar(c, name, value, 0.0, 10.0, &c->theta_sigma_deg);
        }
        if (strcmp(name, "pole_radius_m") == 0) {
            return scalar(c, name, value, 0.0, 1.0, &c->pole_radius_m);
        }
        if (strcmp(name, "near_exclusion_m") == 0) {
            return scalar(c, name, value, 0.0, 20.0, &c->near_exclusion_m);
        }
        if (strcmp(name, "theta_table") == 0) {
            return pairs(c, name, value, add_theta);
        }
        static const char *const info[] = {"tool", "date", "source", "frames", "bin_size_m",
                                            "az_half_window", "usable_azimuths", "ground_start_m",
                                            "near_end_m", "board_theta_table", "unusable",
                                            "edge", "elongation_source"};
        for (size_t i = 0; i < sizeof info / sizeof info[0]; i++) {
            if (strcmp(name, info[i]) == 0) {
                return 1;
            }
        }
        return bad(c, "[calib] %s: unknown key", name);
    }
    if (strcmp(section, "response") == 0) {
        if (strcmp(name, "drops_q8") == 0) {
            return drops(c, value);
        }
        if (strcmp(name, "peaks") == 0 || strcmp(name, "tool") == 0 ||
            strcmp(name, "date") == 0 || strcmp(name, "source") == 0) {
            return 1; // provenance
        }
        return bad(c, "[response] %s: unknown key", name);
    }
    if (strcmp(section, "detect") == 0 && strcmp(name, "elongation") == 0) {
        c->elong_set = true;
        return pairs(c, name, value, add_elong);
    }
    return bad(c, "[%s] %s: unknown section or key", section, name);
}

static int fail(char *err, size_t n, const char *fmt, ...)
{
    va_list ap;
    va_start(ap, fmt);
    vsnprintf(err, n, fmt, ap);
    va_end(ap);
    return -1;
}

static int build(const char *path, ctx_t *c, uint8_t **blob, size_t *len, char *err, size_t n)
{
    const sl_board_t *nom = c->nom;
    const size_t az = nom->azimuths;
    sl_incline_geom_t *const geom = c->geom; // in the caller's context: reentrant
    int16_t *const theta = c->theta;
    uint32_t *const shadow = c->shadow;
    uint16_t *const bins = c->bins;
    if (az > SL_CFG_MAX_AZIMUTHS) {
        return fail(err, n, "%s: board %s has more azimuths than this build holds", path, nom->name);
    }
    const double h_nom = (double)nom->radar_height_um / 1e6;
    const double h = c->height_m > 0 ? c->height_m : h_nom;
    const bool new_h = llround(h * 1e6) != (long long)nom->radar_height_um;
    const double beta = (double)nom->beta_up_cdeg / 100.0;
    const double bin_m = (double)nom->bin_size_um / 1e6;
    for (size_t i = 0; i < az; i++) {
        geom[i] = nom->geom[i];
        theta[i] = nom->theta_cdeg[i];
        shadow[i] = nom->shadow_um[i];
        bins[i] = nom->shadow_bins[i];
        if (!c->have[i] && !new_h) {
            continue; // unusable / not measured: the board's values, bit for bit
        }
        const double th = c->have[i] ? c->theta_deg[i] : (double)nom->theta_cdeg[i] / 100.0;
        if (c->have[i]) {
            geom[i] = slp_geom_make(th, beta);
            theta[i] = (int16_t)llround(th * 100.0);
        }
        const double r = h / tan(th * k_pi / 180.0);
        shadow[i] = (uint32_t)llround(r * 1e6);
        long long last = (long long)floor(r / bin_m) - 1;
        last = last < 0 ? 0 : last > 65535 ? 65535 : last;
        bins[i] = (uint16_t)last;
    }
    sl_board_t v = *nom;
    v.geom = geom;
    v.theta_cdeg = theta;
    v.shadow_um = shadow;
    v.shadow_bins = bins;
    v.radar_height_um = (uint32_t)llround(h * 1e6);
    if (c->theta_sigma_deg >= 0) {
        v.theta_sigma_cdeg = (uint16_t)llround(c->theta_sigma_deg * 100.0);
    }
    if (c->pole_radius_m >= 0) {
        v.pole_radius_um = (uint32_t)llround(c->pole_radius_m * 1e6);
    }
    if (c->near_exclusion_m >= 0) {
        v.near_exclusion_bins = (uint16_t)ceil(c->near_exclusion_m / bin_m);
    }
    if (c->elong_set) {
        memset(v.elong_range_um, 0, sizeof v.elong_range_um);
        memset(v.elong_d_um, 0, sizeof v.elong_d_um);
        v.elong_points = (uint8_t)c->elong_n;
        for (unsigned i = 0; i < c->elong_n; i++) {
            v.elong_range_um[i] = (uint32_t)llround(c->elong_r[i] * 1e6);
            v.elong_d_um[i] = (int32_t)llround(c->elong_d[i] * 1e6);
        }
    }
    if (c->resp_n != 0U && c->resp_n != (unsigned)SL_RESP_TAPS) {
        return fail(err, n, "%s: [response] drops_q8: %u values, this build reads %d (offsets "
                    "-%d..+%d)", path, c->resp_n, SL_RESP_TAPS, SL_CFG_RESP_HALF, SL_CFG_RESP_HALF);
    }
    if (c->resp_n != 0U && !sl_response_plausible(c->resp_q8, 1701)) { // 20 dB, as sl_calblob
        return fail(err, n, "%s: [response] drops_q8: not a plausible response (0 at the centre, "
                    "falling on both sides to 20 dB, half power within %d bins)", path,
                    SL_CFG_RESP_HALF);
    }
    if (c->resp_n != 0U) {
        v.response_prior_q8 = c->resp_q8;
        v.response_calibrated = 1U;
    }
    const size_t size = SL_CALBLOB_BYTES(az) + (c->resp_n != 0U ? SL_CALBLOB_RESPONSE_BYTES : 0U);
    uint8_t *b = malloc(size);
    if (b == NULL) {
        return fail(err, n, "%s: out of memory", path);
    }
    const sl_ssize_t w = sl_calblob_write(&v, b, size);
    if (w < 0) {
        free(b);
        return fail(err, n, "%s: cannot make a blob for board %s: %s", path, nom->name,
                    sl_err_str((sl_err_t)w));
    }
    *blob = b;
    *len = (size_t)w;
    return 0;
}

int slp_calib_file_load(const char *path, const sl_board_t *nominal, uint8_t **blob, size_t *len,
                    char *err, size_t err_size)
{
    *blob = NULL;
    *len = 0;
    FILE *f = fopen(path, "rb");
    if (f == NULL) {
        return fail(err, err_size, "%s: %s", path, strerror(errno));
    }
    uint8_t magic[4] = {0};
    const size_t got = fread(magic, 1, sizeof magic, f);
    if (got == sizeof magic && memcmp(magic, "SLCB", 4) == 0) {
        // A blob: read it whole (bounded: the largest blob this build can open, plus one
        // byte so that an over-long file is reported by sl_calblob_open as a size error).
        const size_t cap = SL_CALBLOB_MAX_BYTES + 1U;
        uint8_t *b = malloc(cap);
        if (b == NULL) {
            fclose(f);
            return fail(err, err_size, "%s: out of memory", path);
        }
        memcpy(b, magic, 4);
        const size_t rest = fread(b + 4, 1, cap - 4U, f);
        fclose(f);
        *blob = b;
        *len = 4U + rest;
        return 0;
    }
    fclose(f);
    ctx_t *c = calloc(1, sizeof *c);
    if (c == NULL) {
        return fail(err, err_size, "%s: out of memory", path);
    }
    c->nom = nominal;
    c->version = 1;
    c->height_m = -1;
    c->theta_sigma_deg = -1;
    c->pole_radius_m = -1;
    c->near_exclusion_m = -1;
    const int line = ini_parse(path, on_entry, c);
    int rc = 0;
    if (line < 0) {
        rc = fail(err, err_size, "%s: cannot read", path);
    } else if (line > 0) {
        rc = fail(err, err_size, "%s:%d: %s", path, line, c->why[0] != '\0' ? c->why : "syntax error");
    } else {
        rc = build(path, c, blob, len, err, err_size);
    }
    free(c);
    return rc;
}
