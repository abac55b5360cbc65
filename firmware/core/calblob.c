// SPDX-License-Identifier: MIT
// Calibration blob: writer, validator and the calibrated board view (sl_calblob.h).
#include <stdbool.h>
#include <stddef.h>
#include <stdint.h>
#include <string.h>

#include "shadowlean/sl_calblob.h"

// Header offsets (sl_calblob.h, "Format").
#define OFF_VERSION 4U
#define OFF_HDR 6U
#define OFF_TOTAL 8U
#define OFF_CRC 12U
#define OFF_NAME 16U
#define OFF_ID 48U
#define OFF_AZ 52U
#define OFF_FLAGS 54U
#define OFF_HEIGHT 56U
#define OFF_RADIUS 60U
#define OFF_NEAR 64U
#define OFF_RSIGMA 66U
#define OFF_TSIGMA 68U
#define OFF_ELONG_N 70U
#define OFF_ELONG_R 72U
#define OFF_ELONG_D 136U

#define HEIGHT_MIN_UM 200000U
#define HEIGHT_MAX_UM 20000000U
#define ELONG_D_MAX_UM 5000000 // the board parser's bounds: |d| <= 5 m, r <= 200 m
#define ELONG_R_MAX_UM 200000000U
#define THETA_SIGMA_MAX_CDEG 1000U
#define RESP_CHECK_LP 1701 // a calibrated response is checked down to 20 dB (20 / 3.0103 x 256)
// Elongation points this build can hold from a blob: the format's slots or the capacity.
#if SL_CFG_MAX_ELONG_POINTS < 16
#define ELONG_CAP ((uint32_t)SL_CFG_MAX_ELONG_POINTS)
#else
#define ELONG_CAP ((uint32_t)SL_CALBLOB_ELONG_POINTS)
#endif

// The wire form of the geometry is the struct's ten 32-bit fields in order: zero copy needs
// the struct to be exactly that (no padding).
_Static_assert(sizeof(sl_incline_geom_t) == SL_CALBLOB_GEOM_BYTES, "geom wire layout");
_Static_assert(offsetof(sl_incline_geom_t, beta_bam32) == 36U, "geom wire layout");
_Static_assert(SL_CALBLOB_AZ_BYTES == SL_CALBLOB_GEOM_BYTES + 4U + 2U + 2U, "azimuth bytes");
_Static_assert((SL_CALBLOB_HEADER_BYTES % 8U) == 0U, "arrays stay aligned");

static uint16_t get16(const uint8_t *b)
{
    return (uint16_t)((uint32_t)b[0] | ((uint32_t)b[1] << 8));
}

static uint32_t get32(const uint8_t *b)
{
    return (uint32_t)b[0] | ((uint32_t)b[1] << 8) | ((uint32_t)b[2] << 16) |
           ((uint32_t)b[3] << 24);
}

static void put16(uint8_t *b, uint32_t v)
{
    b[0] = (uint8_t)(v & 0xFFU);
    b[1] = (uint8_t)((v >> 8) & 0xFFU);
}

static void put32(uint8_t *b, uint32_t v)
{
    b[0] = (uint8_t)(v & 0xFFU);
    b[1] = (uint8_t)((v >> 8) & 0xFFU);
    b[2] = (uint8_t)((v >> 16) & 0xFFU);
    b[3] = (uint8_t)((v >> 24) & 0xFFU);
}

// Length of a board name, counted up to SL_CALBLOB_NAME_BYTES (longer names are refused).
static size_t name_len(const char *s)
{
    size_t n = 0U;
    while (n < SL_CALBLOB_NAME_BYTES && s[n] != '\0') {
        n++;
    }
    return n;
}

static uint32_t fnv_bytes(uint32_t h, const uint8_t *b, size_t n)
{
    uint32_t x = h;
    for (size_t i = 0; i < n; i++) {
        x ^= b[i];
        x *= 16777619U;
    }
    return x;
}

static uint32_t fnv32(uint32_t h, uint32_t v)
{
    uint8_t b[4];
    put32(b, v);
    return fnv_bytes(h, b, sizeof b);
}

uint32_t sl_calblob_board_id(const sl_board_t *board)
{
    if (board == NULL) {
        return 0U;
    }
    uint32_t h = 2166136261U;
    if (board->name != NULL) {
        h = fnv_bytes(h, (const uint8_t *)board->name, name_len(board->name));
    }
    h = fnv32(h, board->azimuths);
    h = fnv32(h, board->encoder_size);
    h = fnv32(h, board->bin_size_um);
    h = fnv32(h, board->range_bins);
    h = fnv32(h, board->roi_bins);
    h = fnv32(h, (uint32_t)board->radar_x_um);
    h = fnv32(h, (uint32_t)board->radar_y_um);
    h = fnv32(h, (uint32_t)board->radar_yaw_cdeg);
    h = fnv32(h, (uint32_t)board->beta_up_cdeg);
    h = fnv32(h, (uint32_t)board->lower_bound_cdeg);
    return h;
}

uint32_t sl_calblob_crc32(uint32_t crc, const uint8_t *data, size_t len)
{
    uint32_t c = ~crc;
    for (size_t i = 0; i < len; i++) {
        c ^= data[i];
        for (unsigned k = 0; k < 8U; k++) {
            c = ((c & 1U) != 0U) ? ((c >> 1) ^ 0xEDB88320U) : (c >> 1);
        }
    }
    return ~c;
}

static uint32_t blob_crc(const uint8_t *b, size_t total)
{
    const uint32_t c = sl_calblob_crc32(0U, b, OFF_CRC);
    return sl_calblob_crc32(c, b + OFF_CRC + 4U, total - (OFF_CRC + 4U));
}

static void geom_put(uint8_t *b, const sl_incline_geom_t *g)
{
    put32(b + 0U, (uint32_t)g->cos_theta_q30);
    put32(b + 4U, (uint32_t)g->sin_theta_q30);
    put32(b + 8U, (uint32_t)g->cos_beta_q30);
    put32(b + 12U, (uint32_t)g->sin_beta_q30);
    put32(b + 16U, (uint32_t)g->cos_tb_q30);
    put32(b + 20U, (uint32_t)g->sin_tb_q30);
    put32(b + 24U, g->rho_amb_q28);
    put32(b + 28U, g->rho_seam_q28);
    put32(b + 32U, g->theta_bam32);
    put32(b + 36U, g->beta_bam32);
}

static void geom_get(sl_incline_geom_t *g, const uint8_t *b)
{
    g->cos_theta_q30 = (sl_q30_t)get32(b + 0U);
    g->sin_theta_q30 = (sl_q30_t)get32(b + 4U);
    g->cos_beta_q30 = (sl_q30_t)get32(b + 8U);
    g->sin_beta_q30 = (sl_q30_t)get32(b + 12U);
    g->cos_tb_q30 = (sl_q30_t)get32(b + 16U);
    g->sin_tb_q30 = (sl_q30_t)get32(b + 20U);
    g->rho_amb_q28 = get32(b + 24U);
    g->rho_seam_q28 = get32(b + 28U);
    g->theta_bam32 = get32(b + 32U);
    g->beta_bam32 = get32(b + 36U);
}

sl_ssize_t sl_calblob_write(const sl_board_t *board, uint8_t *buf, size_t cap)
{
    if (board == NULL || buf == NULL || board->name == NULL || board->geom == NULL ||
        board->theta_cdeg == NULL || board->shadow_um == NULL || board->shadow_bins == NULL ||
        board->azimuths == 0U ||
        name_len(board->name) >= SL_CALBLOB_NAME_BYTES || board->elong_points > ELONG_CAP) {
        return SL_ERR_ARG;
    }
    const size_t az = board->azimuths;
    const bool resp = board->response_calibrated != 0U && board->response_prior_q8 != NULL;
    const size_t total = SL_CALBLOB_BYTES(az) + (resp ? SL_CALBLOB_RESPONSE_BYTES : 0U);
    if (cap < total) {
        return SL_ERR_FULL;
    }
    memset(buf, 0, total);
    buf[0] = (uint8_t)'S';
    buf[1] = (uint8_t)'L';
    buf[2] = (uint8_t)'C';
    buf[3] = (uint8_t)'B';
    put16(buf + OFF_VERSION, SL_CALBLOB_VERSION);
    put16(buf + OFF_HDR, SL_CALBLOB_HEADER_BYTES);
    put32(buf + OFF_TOTAL, (uint32_t)total);
    memcpy(buf + OFF_NAME, board->name, name_len(board->name));
    put32(buf + OFF_ID, sl_calblob_board_id(board));
    put16(buf + OFF_AZ, board->azimuths);
    put16(buf + OFF_FLAGS, resp ? SL_CALBLOB_FLAG_RESPONSE : 0U);
    put32(buf + OFF_HEIGHT, board->radar_height_um);
    put32(buf + OFF_RADIUS, board->pole_radius_um);
    put16(buf + OFF_NEAR, board->near_exclusion_bins);
    put16(buf + OFF_RSIGMA, board->range_sigma_um);
    put16(buf + OFF_TSIGMA, board->theta_sigma_cdeg);
    buf[OFF_ELONG_N] = board->elong_points;
    for (size_t i = 0; i < board->elong_points; i++) {
        put32(buf + OFF_ELONG_R + 4U * i, board->elong_range_um[i]);
        put32(buf + OFF_ELONG_D + 4U * i, (uint32_t)board->elong_d_um[i]);
    }
    uint8_t *const pg = &buf[SL_CALBLOB_HEADER_BYTES];
    uint8_t *const ps = &pg[SL_CALBLOB_GEOM_BYTES * az];
    uint8_t *const pt = &ps[4U * az];
    uint8_t *const pb = &pt[2U * az];
    for (size_t i = 0; i < az; i++) {
        geom_put(&pg[SL_CALBLOB_GEOM_BYTES * i], &board->geom[i]);
        put32(&ps[4U * i], board->shadow_um[i]);
        put16(&pt[2U * i], (uint32_t)(uint16_t)board->theta_cdeg[i]);
        put16(&pb[2U * i], board->shadow_bins[i]);
    }
    if (resp) {
        uint8_t *const pr = &pb[2U * az];
        put16(pr, SL_RESP_TAPS);
        for (size_t i = 0; i < (size_t)SL_RESP_TAPS; i++) {
            put16(&pr[2U + 2U * i], board->response_prior_q8[i]);
        }
    }
    put32(buf + OFF_CRC, blob_crc(buf, total));
    return (sl_ssize_t)total;
}

static bool little_endian(void)
{
    const uint32_t one = 1U;
    uint8_t b[4];
    memcpy(b, &one, sizeof b);
    return b[0] == 1U;
}

static bool aligned4(const uint8_t *p)
{
    // The only integer view of a pointer in the core (MISRA 11.4 advisory, docs/MISRA.md).
    return (((uintptr_t)p) & 3U) == 0U;
}

// theta (0.01 deg) of a bam32 angle, signed, rounded: reuses the estimator's conversion.
static bool bam_matches_cdeg(uint32_t bam, int32_t cdeg)
{
    const int32_t d = sl_incline_bam32_to_cdeg(bam) - cdeg;
    return d >= -1 && d <= 1;
}

// Value checks of one azimuth; returns the failing field or NULL.
static const char *check_az(const sl_board_t *nom, const sl_incline_geom_t *g, int16_t theta,
                            uint32_t shadow_um, uint16_t shadow_bins, uint32_t height_um)
{
    if ((int32_t)theta < SL_INCLINE_THETA_MIN_CDEG || (int32_t)theta > nom->lower_bound_cdeg) {
        return "theta_cdeg";
    }
    if (!sl_incline_geom_ok(g) || !bam_matches_cdeg(g->theta_bam32, theta)) {
        return "geom.theta";
    }
    if (g->beta_bam32 != nom->geom[0].beta_bam32 || g->cos_beta_q30 != nom->geom[0].cos_beta_q30 ||
        g->sin_beta_q30 != nom->geom[0].sin_beta_q30) {
        return "geom.beta";
    }
    if (g->sin_theta_q30 <= 0 || g->cos_theta_q30 <= 0) {
        return "geom.trig";
    }
    // R = H / tan(theta) <=> R sin = H cos, within 1 % of H cos.
    const uint64_t lhs = (uint64_t)shadow_um * (uint64_t)(uint32_t)g->sin_theta_q30;
    const uint64_t rhs = (uint64_t)height_um * (uint64_t)(uint32_t)g->cos_theta_q30;
    const uint64_t diff = (lhs > rhs) ? (lhs - rhs) : (rhs - lhs);
    if (diff > rhs / 100U) {
        return "shadow_um";
    }
    const uint32_t whole = shadow_um / nom->bin_size_um;
    const uint32_t expect = (whole > 0U) ? (whole - 1U) : 0U;
    if ((uint32_t)shadow_bins + 1U < expect || (uint32_t)shadow_bins > expect + 1U ||
        shadow_bins >= nom->roi_bins) {
        return "shadow_bins";
    }
    return NULL;
}

static const char *check_scalars(const uint8_t *b, const sl_board_t *nom, uint32_t *index)
{
    const uint32_t h = get32(b + OFF_HEIGHT);
    if (h < HEIGHT_MIN_UM || h > HEIGHT_MAX_UM) {
        return "radar_height_um";
    }
    if (get16(b + OFF_NEAR) >= nom->roi_bins) {
        return "near_exclusion_bins";
    }
    if (get16(b + OFF_TSIGMA) > THETA_SIGMA_MAX_CDEG) {
        return "theta_sigma_cdeg";
    }
    const uint32_t n = b[OFF_ELONG_N];
    if (n > ELONG_CAP) {
        return "elong_points";
    }
    for (uint32_t i = 0; i < n; i++) {
        const int32_t d = (int32_t)get32(b + OFF_ELONG_D + 4U * i);
        *index = i;
        if (d > ELONG_D_MAX_UM || d < -ELONG_D_MAX_UM) {
            return "elong_d_um";
        }
        const uint32_t r = get32(b + OFF_ELONG_R + 4U * i);
        if (r > ELONG_R_MAX_UM || (i > 0U && r <= get32(b + OFF_ELONG_R + 4U * (i - 1U)))) {
            return "elong_range_um";
        }
    }
    *index = 0U;
    return NULL;
}

// The response section at `pr`: its tap count and a plausible shape (the learner's gates,
// down to 20 dB). NULL when it is usable, else the failed check's name.
static const char *check_response(const uint8_t *pr)
{
    if (get16(pr) != (uint16_t)SL_RESP_TAPS) {
        return "response_taps";
    }
    uint16_t d[SL_RESP_TAPS];
    for (uint32_t i = 0; i < (uint32_t)SL_RESP_TAPS; i++) {
        d[i] = get16(pr + 2U + 2U * i);
    }
    return sl_response_plausible(d, RESP_CHECK_LP) ? NULL : "response";
}

static sl_err_t fail(sl_calblob_info_t *info, sl_err_t e, const char *what, uint32_t index)
{
    if (info != NULL) {
        info->what = what;
        info->index = index;
    }
    return e;
}

sl_err_t sl_calblob_open(const uint8_t *blob, size_t len, const sl_board_t *nominal,
                         sl_calblob_ws_t *ws, sl_board_t *out, sl_calblob_info_t *info)
{
    if (info != NULL) {
        memset(info, 0, sizeof *info);
    }
    if (blob == NULL || nominal == NULL || out == NULL || nominal->name == NULL ||
        nominal->geom == NULL) {
        return fail(info, SL_ERR_ARG, "argument", 0U);
    }
    if (len < SL_CALBLOB_HEADER_BYTES) {
        return fail(info, SL_ERR_CAL_SIZE, "length", 0U);
    }
    if (blob[0] != (uint8_t)'S' || blob[1] != (uint8_t)'L' || blob[2] != (uint8_t)'C' ||
        blob[3] != (uint8_t)'B') {
        return fail(info, SL_ERR_CAL_MAGIC, "magic", 0U);
    }
    const uint16_t version = get16(blob + OFF_VERSION);
    const uint16_t az = get16(blob + OFF_AZ);
    const uint32_t total = get32(blob + OFF_TOTAL);
    if (info != NULL) {
        info->version = version;
        info->azimuths = az;
        info->board_id = get32(blob + OFF_ID);
        info->crc = get32(blob + OFF_CRC);
    }
    if (version != SL_CALBLOB_VERSION) {
        return fail(info, SL_ERR_CAL_VERSION, "version", 0U);
    }
    const uint16_t flags = get16(blob + OFF_FLAGS);
    const bool resp = (flags & SL_CALBLOB_FLAG_RESPONSE) != 0U;
    if (get16(blob + OFF_HDR) != SL_CALBLOB_HEADER_BYTES || (size_t)total != len ||
        (size_t)total != SL_CALBLOB_BYTES(az) + (resp ? SL_CALBLOB_RESPONSE_BYTES : 0U)) {
        return fail(info, SL_ERR_CAL_SIZE, "size", 0U);
    }
    if (blob_crc(blob, total) != get32(blob + OFF_CRC)) {
        return fail(info, SL_ERR_CAL_CRC, "crc", 0U);
    }
    const size_t nlen = name_len(nominal->name);
    if (nlen >= SL_CALBLOB_NAME_BYTES || memcmp(blob + OFF_NAME, nominal->name, nlen) != 0 ||
        blob[OFF_NAME + nlen] != 0U) {
        return fail(info, SL_ERR_CAL_BOARD, "name", 0U);
    }
    if (az != nominal->azimuths || az > SL_CFG_MAX_AZIMUTHS) {
        return fail(info, SL_ERR_CAL_AZIMUTHS, "azimuths", 0U);
    }
    if (get32(blob + OFF_ID) != sl_calblob_board_id(nominal)) {
        return fail(info, SL_ERR_CAL_BOARD, "board_id", 0U);
    }
    if ((flags & (uint16_t)~SL_CALBLOB_FLAG_RESPONSE) != 0U) {
        return fail(info, SL_ERR_CAL_VALUE, "flags", 0U);
    }
    uint32_t index = 0U;
    const char *bad = check_scalars(blob, nominal, &index);
    if (bad != NULL) {
        return fail(info, SL_ERR_CAL_VALUE, bad, index);
    }
    const uint8_t *pg = blob + SL_CALBLOB_HEADER_BYTES;
    const uint8_t *ps = pg + SL_CALBLOB_GEOM_BYTES * (size_t)az;
    const uint8_t *pt = ps + 4U * (size_t)az;
    const uint8_t *pb = pt + 2U * (size_t)az;
    const uint32_t height = get32(blob + OFF_HEIGHT);
    for (uint32_t i = 0; i < az; i++) {
        sl_incline_geom_t g;
        geom_get(&g, pg + SL_CALBLOB_GEOM_BYTES * i);
        const char *w = check_az(nominal, &g, (int16_t)get16(pt + 2U * i), get32(ps + 4U * i),
                                 get16(pb + 2U * i), height);
        if (w != NULL) {
            return fail(info, SL_ERR_CAL_VALUE, w, i);
        }
    }
    const uint8_t *pr = pb + 2U * (size_t)az;
    if (resp) {
        const char *w = check_response(pr);
        if (w != NULL) {
            return fail(info, SL_ERR_CAL_VALUE, w, 0U);
        }
    }
    const bool in_place = little_endian() && aligned4(blob);
    if (!in_place && ws == NULL) {
        return fail(info, SL_ERR_CAL_WORKSPACE, "workspace", 0U);
    }
    sl_board_t v = *nominal;
    v.radar_height_um = height;
    v.pole_radius_um = get32(blob + OFF_RADIUS);
    v.near_exclusion_bins = get16(blob + OFF_NEAR);
    v.range_sigma_um = get16(blob + OFF_RSIGMA);
    v.theta_sigma_cdeg = get16(blob + OFF_TSIGMA);
    v.elong_points = blob[OFF_ELONG_N];
    for (uint32_t i = 0; i < SL_CFG_MAX_ELONG_POINTS; i++) {
        const bool used = i < (uint32_t)v.elong_points;
        v.elong_range_um[i] = used ? get32(blob + OFF_ELONG_R + 4U * i) : 0U;
        v.elong_d_um[i] = used ? (int32_t)get32(blob + OFF_ELONG_D + 4U * i) : 0;
    }
    if (in_place) {
        // Little-endian and aligned: the wire form is the in-memory form (static asserts
        // above); MISRA 11.5 as recorded in docs/MISRA.md.
        v.geom = (const sl_incline_geom_t *)(const void *)pg;
        v.shadow_um = (const uint32_t *)(const void *)ps;
        v.theta_cdeg = (const int16_t *)(const void *)pt;
        v.shadow_bins = (const uint16_t *)(const void *)pb;
        if (resp) {
            v.response_prior_q8 = (const uint16_t *)(const void *)(pr + 2U);
        }
    } else {
        for (uint32_t i = 0; i < az; i++) {
            geom_get(&ws->geom[i], pg + SL_CALBLOB_GEOM_BYTES * i);
            ws->shadow_um[i] = get32(ps + 4U * i);
            ws->theta_cdeg[i] = (int16_t)get16(pt + 2U * i);
            ws->shadow_bins[i] = get16(pb + 2U * i);
        }
        v.geom = ws->geom;
        v.shadow_um = ws->shadow_um;
        v.theta_cdeg = ws->theta_cdeg;
        v.shadow_bins = ws->shadow_bins;
        if (resp) {
            for (uint32_t i = 0; i < (uint32_t)SL_RESP_TAPS; i++) {
                ws->response_q8[i] = get16(pr + 2U + 2U * i);
            }
            v.response_prior_q8 = ws->response_q8;
        }
    }
    v.response_calibrated = resp ? 1U : 0U;
    if (info != NULL) {
        info->zero_copy = in_place;
    }
    *out = v;
    return SL_OK;
}
