// SPDX-License-Identifier: MIT
// Unit tests for the generated board tables and the board registry (sl_board.h).
// The expected values are recomputed here in double precision from the geometry the
// board files state (MATH.md s.1), independently of the generator.
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <cmocka.h>
#include <math.h>

#include "shadowlean/sl_board.h"

static const double kPi = 3.14159265358979323846;

static double q30(int32_t v) { return (double)v / 1073741824.0; }
static double uq28(uint32_t v) { return (double)v / 268435456.0; }
static double bam32_deg(uint32_t v) { return (double)(int32_t)v * 360.0 / 4294967296.0; }

static void test_board_registry_finds_every_board_by_name(void **state)
{
    (void)state;
    assert_true(sl_board_count() >= 3U);
    assert_non_null(sl_board_find("paper-sim"));
    assert_non_null(sl_board_find("paper-bench"));
    assert_non_null(sl_board_find("robotcar-leaf"));
    assert_null(sl_board_find("paper"));
    assert_null(sl_board_find("paper-sim-2"));
    assert_null(sl_board_find(""));
    assert_null(sl_board_find(NULL));
    assert_null(sl_board_at(sl_board_count()));
    for (size_t i = 0; i < sl_board_count(); i++) {
        assert_ptr_equal(sl_board_find(sl_board_at(i)->name), sl_board_at(i));
    }
}

static void test_board_paper_sim_has_theta_26_on_every_azimuth(void **state)
{
    (void)state;
    const sl_board_t *b = sl_board_find("paper-sim");
    assert_non_null(b);
    assert_int_equal(b->azimuths, 400);
    assert_int_equal(b->encoder_size, 5600);
    assert_int_equal(b->bin_size_um, 43800);
    assert_int_equal(b->radar_height_um, 2580000);
    assert_int_equal(b->beta_up_cdeg, 0);
    const double r_shadow = 2.58 / tan(26.0 * kPi / 180.0);
    for (unsigned i = 0; i < b->azimuths; i++) {
        assert_int_equal(b->theta_cdeg[i], 2600);
        assert_true(fabs(b->shadow_um[i] * 1e-6 - r_shadow) < 2e-6);
        // bin k spans [k b, (k + 1) b): the last bin wholly inside the shadow
        assert_int_equal(b->shadow_bins[i], (unsigned)floor(r_shadow / 0.0438) - 1U);
        assert_true(fabs(bam32_deg(b->geom[i].theta_bam32) - 26.0) < 1e-6);
    }
}

static void test_board_geometry_entries_are_consistent(void **state)
{
    (void)state;
    for (size_t k = 0; k < sl_board_count(); k++) {
        const sl_board_t *b = sl_board_at(k);
        for (unsigned i = 0; i < b->azimuths; i++) {
            const sl_incline_geom_t *g = &b->geom[i];
            const double th = bam32_deg(g->theta_bam32) * kPi / 180.0;
            const double be = bam32_deg(g->beta_bam32) * kPi / 180.0;
            assert_true(fabs(th * 18000.0 / kPi - b->theta_cdeg[i]) <= 0.5 + 1e-9);
            assert_true(fabs(be * 18000.0 / kPi - b->beta_up_cdeg) <= 0.5 + 1e-9);
            // rounded once to nearest: within half an LSB (+ the angle's own rounding)
            assert_true(fabs(q30(g->cos_theta_q30) - cos(th)) < 3e-9);
            assert_true(fabs(q30(g->sin_theta_q30) - sin(th)) < 3e-9);
            assert_true(fabs(q30(g->cos_beta_q30) - cos(be)) < 3e-9);
            assert_true(fabs(q30(g->sin_beta_q30) - sin(be)) < 3e-9);
            assert_true(fabs(q30(g->cos_tb_q30) - cos(th + be)) < 3e-9);
            assert_true(fabs(q30(g->sin_tb_q30) - sin(th + be)) < 3e-9);
            assert_true(fabs(uq28(g->rho_amb_q28) - 1.0 / cos((th + be) / 2.0)) < 1e-8);
            assert_true(fabs(uq28(g->rho_seam_q28) - 1.0 / cos(th + be)) < 1e-8);
            // ground shadow radius H / tan(theta), and the bins inside it
            const double r = b->radar_height_um * 1e-6 / tan(th);
            assert_true(fabs(b->shadow_um[i] * 1e-6 - r) < 1e-5);
            assert_true((b->shadow_bins[i] + 1U) * b->bin_size_um <= b->shadow_um[i]);
            assert_true((b->shadow_bins[i] + 2U) * b->bin_size_um > b->shadow_um[i]);
            assert_true(b->theta_cdeg[i] > 100 && b->theta_cdeg[i] < b->lower_bound_cdeg);
        }
        assert_true(b->roi_bins <= SL_CFG_ROI_BINS && b->roi_bins % 32U == 0U);
        assert_true(b->mask_frames >= 1U && b->mask_frames <= SL_CFG_MASK_FRAMES_MAX);
        assert_true(b->near_exclusion_bins < b->roi_bins);
        assert_true(b->elong_points <= SL_CFG_MAX_ELONG_POINTS);
    }
}

static void test_board_robotcar_leaf_shadow_is_longer_behind_than_beside(void **state)
{
    (void)state;
    // REAL_SCANS.md s.2: the dark ring sits at ~3.0-3.5 m beside the car and ~4.2 m behind.
    const sl_board_t *b = sl_board_find("robotcar-leaf");
    assert_non_null(b);
    const unsigned rear = b->azimuths / 2U, left = 3U * b->azimuths / 4U, right = b->azimuths / 4U;
    assert_true(b->shadow_um[rear] > 4000000U && b->shadow_um[rear] < 4500000U);
    assert_true(b->shadow_um[left] > 3000000U && b->shadow_um[left] < 3700000U);
    assert_true(b->shadow_um[right] > 3000000U && b->shadow_um[right] < 3700000U);
    assert_true(b->shadow_um[0] > 3300000U && b->shadow_um[0] < 3900000U);
    int varies = 0;
    for (unsigned i = 1; i < b->azimuths; i++) {
        varies |= b->theta_cdeg[i] != b->theta_cdeg[0];
    }
    assert_true(varies);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_board_registry_finds_every_board_by_name),
        cmocka_unit_test(test_board_paper_sim_has_theta_26_on_every_azimuth),
        cmocka_unit_test(test_board_geometry_entries_are_consistent),
        cmocka_unit_test(test_board_robotcar_leaf_shadow_is_longer_behind_than_beside),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
