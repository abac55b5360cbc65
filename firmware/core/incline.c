// SPDX-License-Identifier: MIT
// Inclination estimator (sl_incline.h): integer-only, no state, no float.
//
// Q formats used inside (also listed in sl_incline.h):
//   rho        UQ4.28 (uint32)       rho^2, Q, rho*sqrt(rho^2-1)    Q56 (64-bit)
//   N, D       Q58 (int64) -> Q27     atan ratio                     UQ2.30 in [0, 1]
//   angles     bam32 (2^32 / turn)    derivatives K, g               UQ8.24
//   sigma terms  0.01 deg in Q12 (saturated at 65536 cdeg each)
// Stack (arm-none-eabi-gcc, -mcpu=cortex-m0 -Os, -fstack-usage): sl_incline_estimate 88 B,
// sl_incline_atan2_bam32 32 B, sl_incline_geom_ok 24 B, sl_fx_isqrt64 40 B; plus libgcc's
// 64-bit division. No recursion, no arrays on the stack. Flash: 2500 B incl. the table.
#include <stdbool.h>
#include <stddef.h>
#include <stdint.h>

#include "shadowlean/sl_err.h"
#include "shadowlean/sl_fx.h"
#include "shadowlean/sl_incline.h"

// atan(i / 256) for i = 0..256 as bam32 (2^32 = one turn), rounded to nearest; entry 256
// (= 45 deg = 2^29) is the guard entry for the interpolation. Generated once with:
//   python3 -c "import math; print([int(math.floor(math.atan(i/256)/(2*math.pi)*2**32+0.5))
//               for i in range(257)])"
// and checked entry by entry against libm by tests/core/test_incline.c. ROM: 1028 bytes.
static const uint32_t atan_bam32[257] = {
    0U, 2670163U, 5340245U, 8010164U, 10679838U, 13349187U,
    16018129U, 18686582U, 21354465U, 24021698U, 26688200U, 29353889U,
    32018685U, 34682507U, 37345276U, 40006910U, 42667331U, 45326458U,
    47984212U, 50640513U, 53295284U, 55948444U, 58599915U, 61249621U,
    63897482U, 66543421U, 69187361U, 71829226U, 74468939U, 77106424U,
    79741605U, 82374407U, 85004756U, 87632577U, 90257796U, 92880340U,
    95500135U, 98117110U, 100731191U, 103342309U, 105950391U, 108555367U,
    111157167U, 113755721U, 116350962U, 118942819U, 121531227U, 124116117U,
    126697423U, 129275078U, 131849018U, 134419178U, 136985493U, 139547900U,
    142106335U, 144660738U, 147211045U, 149757197U, 152299132U, 154836791U,
    157370116U, 159899047U, 162423527U, 164943499U, 167458907U, 169969696U,
    172475810U, 174977196U, 177473799U, 179965568U, 182452450U, 184934394U,
    187411349U, 189883266U, 192350096U, 194811789U, 197268300U, 199719579U,
    202165583U, 204606264U, 207041579U, 209471483U, 211895933U, 214314887U,
    216728303U, 219136141U, 221538359U, 223934919U, 226325781U, 228710908U,
    231090262U, 233463808U, 235831508U, 238193329U, 240549235U, 242899194U,
    245243172U, 247581137U, 249913059U, 252238905U, 254558647U, 256872255U,
    259179700U, 261480955U, 263775993U, 266064788U, 268347313U, 270623543U,
    272893455U, 275157025U, 277414230U, 279665048U, 281909457U, 284147437U,
    286378966U, 288604026U, 290822599U, 293034664U, 295240206U, 297439207U,
    299631651U, 301817523U, 303996806U, 306169488U, 308335554U, 310494991U,
    312647786U, 314793928U, 316933406U, 319066208U, 321192324U, 323311746U,
    325424463U, 327530468U, 329629752U, 331722309U, 333808132U, 335887214U,
    337959550U, 340025134U, 342083962U, 344136031U, 346181336U, 348219874U,
    350251643U, 352276640U, 354294865U, 356306316U, 358310992U, 360308894U,
    362300021U, 364284375U, 366261957U, 368232767U, 370196809U, 372154086U,
    374104599U, 376048352U, 377985350U, 379915596U, 381839095U, 383755852U,
    385665872U, 387569162U, 389465727U, 391355574U, 393238710U, 395115141U,
    396984877U, 398847924U, 400704291U, 402553986U, 404397019U, 406233399U,
    408063135U, 409886237U, 411702716U, 413512582U, 415315845U, 417112518U,
    418902610U, 420686135U, 422463104U, 424233528U, 425997422U, 427754796U,
    429505665U, 431250041U, 432987938U, 434719370U, 436444350U, 438162893U,
    439875013U, 441580724U, 443280042U, 444972981U, 446659557U, 448339785U,
    450013680U, 451681259U, 453342536U, 454997530U, 456646255U, 458288728U,
    459924966U, 461554985U, 463178803U, 464796437U, 466407904U, 468013221U,
    469612406U, 471205476U, 472792449U, 474373344U, 475948178U, 477516969U,
    479079736U, 480636498U, 482187271U, 483732076U, 485270931U, 486803855U,
    488330866U, 489851983U, 491367227U, 492876615U, 494380167U, 495877903U,
    497369841U, 498856002U, 500336404U, 501811068U, 503280012U, 504743258U,
    506200824U, 507652730U, 509098996U, 510539643U, 511974689U, 513404156U,
    514828063U, 516246430U, 517659277U, 519066625U, 520468494U, 521864904U,
    523255875U, 524641427U, 526021581U, 527396357U, 528765775U, 530129856U,
    531488619U, 532842087U, 534190278U, 535533213U, 536870912U,
};

#define ATAN_FRAC_BITS 22U                     // Q30 ratio = 8 index bits + 22 fraction bits
#define BAM_90 ((sl_bam32_t)1U << 30)
#define BAM_180 ((sl_bam32_t)1U << 31)
#define ONE_Q28 ((uint64_t)1U << 28)
#define ONE_Q56 ((uint64_t)1U << 56)
#define SAT_Q12 ((uint64_t)65536U << 12)       // each sigma term saturates at 655.36 deg
#define CDEG_PER_RAD_Q16 375493621U            // round(18000 / pi * 2^16)

static uint32_t uabs32(int32_t v)
{
    // Unsigned negation: well defined for INT32_MIN too.
    return (v < 0) ? (uint32_t)0U - (uint32_t)v : (uint32_t)v;
}

static int32_t bam_signed(sl_bam32_t a)
{
    // Two's complement reinterpretation without implementation-defined conversion.
    return (a >= BAM_180) ? -(int32_t)(~a) - 1 : (int32_t)a;
}

sl_bam32_t sl_incline_atan2_bam32(int32_t y, int32_t x)
{
    const uint32_t ax = uabs32(x);
    const uint32_t ay = uabs32(y);
    if (ax == 0U && ay == 0U) {
        return 0U;
    }
    // Octant reduction: ratio of the smaller to the larger magnitude, in [0, 1].
    const bool swap = ay > ax;
    const uint32_t num = swap ? ax : ay;
    const uint32_t den = swap ? ay : ax;
    const uint32_t z = (uint32_t)(((uint64_t)num << 30) / den);
    uint32_t idx = z >> ATAN_FRAC_BITS;
    uint32_t frac = z & ((1U << ATAN_FRAC_BITS) - 1U);
    if (idx >= 256U) { // z == 1 exactly: last interval at its end
        idx = 255U;
        frac = 1U << ATAN_FRAC_BITS;
    }
    const uint32_t a0 = atan_bam32[idx];
    const uint32_t step = atan_bam32[idx + 1U] - a0; // atan is increasing: no wrap
    sl_bam32_t a = a0 + (uint32_t)sl_fx_urshift_round64((uint64_t)step * frac, ATAN_FRAC_BITS);
    if (swap) {
        a = BAM_90 - a;
    }
    if (x < 0) {
        a = BAM_180 - a;
    }
    if (y < 0) {
        a = (sl_bam32_t)0U - a; // modular negation: the angle's mirror image
    }
    return a;
}

int32_t sl_incline_bam32_to_cdeg(sl_bam32_t angle)
{
    // |angle| * 36000 < 2^47: no overflow; result in [-18000, 18000].
    return (int32_t)sl_fx_rshift_round64((int64_t)bam_signed(angle) * 36000, 32U);
}

// True when lo_cdeg <= angle <= hi_cdeg within one bam32 LSB (so that a limit written by
// the host, e.g. 60 deg rounded to nearest bam32, is inside): angle_bam * 36000 against
// limit_cdeg * 2^32 +- 36000 (all below 2^53, exact).
static bool bam_in_cdeg(int64_t angle_bam, int64_t lo_cdeg, int64_t hi_cdeg)
{
    const int64_t a = angle_bam * 36000;
    return a >= lo_cdeg * 4294967296LL - 36000 && a <= hi_cdeg * 4294967296LL + 36000;
}

bool sl_incline_geom_ok(const sl_incline_geom_t *geom)
{
    if (geom == NULL) {
        return false;
    }
    const int64_t t = bam_signed(geom->theta_bam32);
    const int64_t b = bam_signed(geom->beta_bam32);
    return bam_in_cdeg(t, SL_INCLINE_THETA_MIN_CDEG, SL_INCLINE_THETA_MAX_CDEG) &&
           bam_in_cdeg(b, SL_INCLINE_BETA_MIN_CDEG, SL_INCLINE_BETA_MAX_CDEG) &&
           bam_in_cdeg(t + b, SL_INCLINE_WEDGE_MIN_CDEG, SL_INCLINE_WEDGE_MAX_CDEG) &&
           geom->rho_amb_q28 > SL_UQ4_28_ONE && geom->rho_amb_q28 <= geom->rho_seam_q28 &&
           geom->rho_seam_q28 < UINT32_MAX && geom->sin_tb_q30 > 0 && geom->cos_tb_q30 > 0;
}

// Branch 1: alpha = atan2(rho cos t - cos b, rho sin t + sin b).
static sl_bam32_t alpha_branch1(uint32_t rho_q28, const sl_incline_geom_t *g)
{
    // Q28 x Q30 = Q58; |rho| < 10 so every product is below 2^62.
    const int64_t r = (int64_t)rho_q28;
    const int64_t n_q58 = r * g->cos_theta_q30 - (int64_t)g->cos_beta_q30 * (int64_t)ONE_Q28;
    const int64_t d_q58 = r * g->sin_theta_q30 + (int64_t)g->sin_beta_q30 * (int64_t)ONE_Q28;
    // Q58 -> Q27: |N|, |D| <= 11 < 16, fits int32.
    const int32_t n_q27 = sl_fx_sat32(sl_fx_rshift_round64(n_q58, 31U));
    const int32_t d_q27 = sl_fx_sat32(sl_fx_rshift_round64(d_q58, 31U));
    return sl_incline_atan2_bam32(n_q27, d_q27);
}

// 1-sigma uncertainty in 0.01 deg; k_q24 = |d alpha / d rho|, g_q24 = |d alpha / d theta|.
static uint16_t sigma_cdeg(uint32_t rho_q28, uint64_t k_q24, uint64_t g_q24, uint32_t r1,
                           uint32_t sigma_r, uint16_t sigma_theta_cdeg)
{
    if (sigma_r >= r1) {
        return UINT16_MAX; // sigma_r / r1 >= 1: no meaningful number, saturate
    }
    // sqrt(1 + rho^2) in Q28 (< 10.05 * 2^28 < 2^32).
    const uint64_t sq1_q28 = sl_fx_isqrt64((uint64_t)rho_q28 * rho_q28 + ONE_Q56);
    // M = K * sqrt(1 + rho^2): rad per unit of sigma_r / r1, <= 163 in the domain.
    const uint64_t m_q20 = sl_fx_urshift_round64(k_q24 * sq1_q28, 32U);
    const uint64_t mc_q10 = sl_fx_urshift_round64(m_q20 * CDEG_PER_RAD_Q16, 26U); // cdeg
    const uint64_t ratio_q32 = ((uint64_t)sigma_r << 32) / r1;                   // < 1
    uint64_t a_q12 = sl_fx_urshift_round64(mc_q10 * ratio_q32, 30U);
    uint64_t b_q12 = sl_fx_urshift_round64(g_q24 * sigma_theta_cdeg, 12U);
    a_q12 = (a_q12 > SAT_Q12) ? SAT_Q12 : a_q12;
    b_q12 = (b_q12 > SAT_Q12) ? SAT_Q12 : b_q12;
    const uint64_t s_q12 = sl_fx_isqrt64(a_q12 * a_q12 + b_q12 * b_q12); // <= 2^28.5
    const uint64_t s = sl_fx_urshift_round64(s_q12, 12U);
    return (s > UINT16_MAX) ? (uint16_t)UINT16_MAX : (uint16_t)s;
}

sl_incline_result_t sl_incline_estimate(uint32_t r1_um, uint32_t r2_um,
                                        const sl_incline_geom_t *geom, uint32_t sigma_r_um,
                                        uint16_t sigma_theta_cdeg)
{
    sl_incline_result_t res = {0};
    SL_ASSERT(geom != NULL);
    res.branch = (uint8_t)SL_INCLINE_BRANCH_NONE;
    if (!sl_incline_geom_ok(geom)) {
        res.flag = (uint8_t)SL_INCLINE_OUT_OF_DOMAIN;
        return res;
    }
    if (r1_um == 0U || r1_um >= r2_um) {
        res.flag = (uint8_t)SL_INCLINE_INVALID;
        return res;
    }
    const uint64_t rho64 = ((uint64_t)r2_um << 28) / r1_um; // floor, UQ4.28
    if (rho64 > SL_INCLINE_RHO_MAX_Q28) {
        res.rho_q28 = (rho64 >= UINT32_MAX) ? UINT32_MAX : (uint32_t)rho64;
        res.flag = (uint8_t)SL_INCLINE_OUT_OF_DOMAIN;
        return res;
    }
    const uint32_t rho = (uint32_t)rho64;
    res.rho_q28 = rho;
    if (rho < geom->rho_amb_q28) {
        res.flag = (uint8_t)SL_INCLINE_AMBIGUOUS;
        return res;
    }
    const uint64_t rho2_q56 = (uint64_t)rho * rho; // <= 100 * 2^56 < 2^63
    uint64_t k_q24;
    uint64_t g_q24;
    if (rho >= geom->rho_seam_q28) {
        res.branch = (uint8_t)SL_INCLINE_BRANCH_1;
        res.alpha_bam32 = alpha_branch1(rho, geom);
        // Q = rho^2 - 2 rho cos(t+b) + 1 >= sin^2(t+b) > 3e-4 (Q56, positive).
        const int64_t rc_q58 = (int64_t)rho * geom->cos_tb_q30; // >= 0
        const uint64_t q_q56 = rho2_q56 + ONE_Q56 - (uint64_t)sl_fx_rshift_round64(rc_q58, 1U);
        const uint64_t q_q32 = sl_fx_urshift_round64(q_q56, 24U);
        // rho (rho - cos(t+b)) >= 0 on branch 1 (rho >= 1/cos(t+b) >= cos(t+b)).
        const uint64_t num_q56 = rho2_q56 - (uint64_t)sl_fx_rshift_round64(rc_q58, 2U);
        k_q24 = ((uint64_t)(uint32_t)geom->sin_tb_q30 << 26) / q_q32; // sin(t+b) / Q
        g_q24 = num_q56 / q_q32;                                       // rho (rho - c) / Q
    } else {
        res.branch = (uint8_t)SL_INCLINE_BRANCH_2;
        // sqrt(rho^2 - 1) in Q28, exact floor; < rho_seam < 3.9 so it fits int32.
        const uint32_t sm_q28 = sl_fx_isqrt64(rho2_q56 - ONE_Q56);
        res.alpha_bam32 = sl_incline_atan2_bam32((int32_t)sm_q28, (int32_t)ONE_Q28) -
                          geom->theta_bam32;
        // 1 / (rho sqrt(rho^2 - 1)); the product is >= 0.0087 in the domain.
        const uint64_t p_q32 = sl_fx_urshift_round64((uint64_t)rho * sm_q28, 24U);
        k_q24 = ONE_Q56 / p_q32;
        g_q24 = (uint64_t)1U << 24;
    }
    res.alpha_cdeg = sl_incline_bam32_to_cdeg(res.alpha_bam32);
    res.sigma_cdeg = sigma_cdeg(rho, k_q24, g_q24, r1_um, sigma_r_um, sigma_theta_cdeg);
    res.flag = (uint8_t)SL_INCLINE_VALID;
    return res;
}

uint32_t sl_incline_bounds_sigma_um(uint32_t r1_um, uint32_t r2_um, uint32_t s1_um,
                                    uint32_t s2_um)
{
    // sigma_rho^2 = (s2^2 + rho^2 s1^2) / r1^2 = s_eff^2 (1 + rho^2) / r1^2 with
    // s_eff^2 = w s2^2 + (1 - w) s1^2, w = r1^2 / (r1^2 + r2^2) (Q16, ranges in mm).
    const uint64_t a = (uint64_t)(r1_um / 1000U) * (r1_um / 1000U);
    const uint64_t c = (uint64_t)(r2_um / 1000U) * (r2_um / 1000U);
    const uint64_t w = a + c == 0U ? 32768U : (a << 16) / (a + c);
    const uint64_t v = w * ((uint64_t)s2_um * s2_um) + (65536U - w) * ((uint64_t)s1_um * s1_um);
    return sl_fx_isqrt64(sl_fx_urshift_round64(v, 16U));
}

#if SL_CFG_FIT
uint32_t sl_incline_bounds_sigma_corr_um(uint32_t r1_um, uint32_t r2_um, uint32_t s1_um,
                                         uint32_t s2_um, int32_t corr_q15)
{
    const uint32_t s = sl_incline_bounds_sigma_um(r1_um, r2_um, s1_um, s2_um);
    if (corr_q15 == 0 || s1_um > (1U << 24) || s2_um > (1U << 24)) {
        return s; // no correlation, or sigmas of 16 m and more: s^2 alone (64-bit range)
    }
    // the cross term 2 corr s1 s2 r1 r2 / (r1^2 + r2^2) (ranges in mm), taken off s^2
    const uint64_t a = (uint64_t)(r1_um / 1000U), c = (uint64_t)(r2_um / 1000U);
    const uint64_t den = a * a + c * c;
    const int32_t k = corr_q15 > 32767 ? 32767 : (corr_q15 < -32767 ? -32767 : corr_q15);
    const uint64_t w2 = den == 0U ? 65536U : ((2U * a * c) << 16) / den; // <= 1, Q16
    const uint64_t x = ((uint64_t)s1_um * s2_um * w2) >> 16;
    const uint64_t cross = (x * (uint64_t)(k < 0 ? -k : k)) >> 15;
    const uint64_t s2 = (uint64_t)s * s;
    if (k < 0) {
        return sl_fx_isqrt64(s2 + cross);
    }
    return sl_fx_isqrt64(s2 > cross ? s2 - cross : 0U);
}
#endif
