// SPDX-License-Identifier: MIT
// The ground on the bus: scenes/ground_dropoff.ini (paper-sim at 1 m/s towards a 0.2 m
// drop-off 12 m ahead, CTS350-X physics) rendered by the simulator and fed to the core
// pipeline with its ground on and the scene's speed as the motion input; every CAN frame
// the pipeline hands its port is decoded with the core's decoders and its Profile 11 check.
// Asserted: one GroundPlane per rotation, before that rotation's Status, in sequence; the
// plane's height and attitude within the scene's truth once it is GOOD; a GroundHazard DROP
// ahead (within 45 deg of forward), 0.2 m lower; every GroundHazard frame one of the ground
// module's confirmed sectors with its values (on the signals' grid); never a STEP.
#include <cmath>
#include <cstdarg>
#include <cstddef>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <memory>
#include <setjmp.h>
#include <string>
#include <vector>

extern "C" {
#include <cmocka.h>
#include "shadowlean/sl_board.h"
#include "shadowlean/sl_can.h"
#include "shadowlean/sl_ground.h"
#include "shadowlean/sl_pipeline.h"
}

#include "sim_eval.h"
#include "sim_render.h"
#include "sim_scene.h"
#include "sl_paths.h"

using namespace sl;

namespace {

struct Sent {
    int rotation;       // rotations completed when the frame was sent (its rotation: this - 1)
    sl_can_frame_t f;
};

struct Run {
    std::vector<Sent> frames;
    int rotations = 0;
    double height_m = 0;
    std::unique_ptr<sl_pipeline_t> p;
    // per rotation, the ground module's sectors at its end
    std::vector<std::vector<sl_ground_sector_t>> sectors;
};

Run g_run;
const sl_board_t *g_board = nullptr;

sl_err_t record(void *ctx, const sl_can_frame_t *f)
{
    Run *r = static_cast<Run *>(ctx);
    r->frames.push_back({static_cast<int>(r->p->stats.rotations), *f});
    return SL_OK;
}

// After the ground's rotation end and before the rotation's frames: its confirmed sectors.
void on_rotation(void *ctx, const sl_pipeline_rotation_t *)
{
    Run *r = static_cast<Run *>(ctx);
    r->sectors.emplace_back(r->p->ground.sec, r->p->ground.sec + SL_CFG_GROUND_SECTORS);
}

int setup(void **)
{
    Scene scene = load_scene(source_dir() + "/scenes/ground_dropoff.ini");
    const Simulator sim(scene);
    const PipeCfg pc = pipe_cfg_for_scene(scene);
    g_board = sl_board_find(pc.board.c_str());
    if (g_board == nullptr) {
        return -1;
    }
    sl_pipeline_cfg_t cfg;
    sl_pipeline_cfg_default(&cfg, g_board);
    if (pc.threshold >= 0) {
        cfg.threshold = static_cast<uint16_t>(pc.threshold);
    }
    if (pc.profile >= 0) {
        cfg.profile = pc.profile != 0;
    }
    cfg.value_scale = scene_value_scale(scene);
    cfg.port.can_tx = record;
    cfg.port.on_rotation = on_rotation;
    cfg.port.ctx = &g_run;
    g_run.p.reset(new sl_pipeline_t());
    if (sl_pipeline_init(g_run.p.get(), g_board, &cfg) != SL_OK || !g_run.p->cfg.ground) {
        return -1;
    }
    sl_pipeline_set_link_state(g_run.p.get(), SL_CAN_LINK_STREAMING);
    g_run.height_m = scene.board.radar_height_m + scene.height_offset_m;
    const uint64_t period = static_cast<uint64_t>(std::llround(1e6 / scene.rotation_hz));
    const auto cfgmsg = sim.config_message();
    sl_pipeline_feed(g_run.p.get(), cfgmsg.data(), cfgmsg.size(), 1000000U);
    sim_run(sim, 0, scene.rotations, 2, [&](int k, std::vector<uint8_t> &bytes, std::vector<GtRow> &) {
        const uint64_t now = 1000000U + static_cast<uint64_t>(k) * period;
        sl_pipeline_set_motion(g_run.p.get(), static_cast<int32_t>(std::lround(scene.speed_mps * 1000)), true, 0,
                               true, now);
        sl_pipeline_feed(g_run.p.get(), bytes.data(), bytes.size(), now + period / 2);
    });
    g_run.rotations = static_cast<int>(g_run.p->stats.rotations);
    std::printf("ground_dropoff: %d rotations, %zu CAN frames\n", g_run.rotations, g_run.frames.size());
    return 0;
}

const sl_can_e2e_cfg_t *e2e(sl_can_msg_t m)
{
    return &sl_can_e2e_defaults[m];
}

// round(x / d) x d, halves up (the encoder's rounding, sl_can.h)
int64_t on_grid(int64_t x, int64_t d)
{
    return static_cast<int64_t>(std::floor(static_cast<double>(x) / static_cast<double>(d) + 0.5)) * d;
}

} // namespace

// One GroundPlane per rotation, after the rotation's LeanWarning and before its Status, its
// counter in sequence (Profile 11 OK on every frame after the first).
static void test_ground_plane_once_per_rotation_before_status(void **)
{
    assert_true(g_run.rotations >= 50);
    std::vector<int> planes(static_cast<size_t>(g_run.rotations) + 1, 0);
    sl_can_e2e_rx_t rx;
    sl_can_e2e_rx_init(&rx, 1U);
    int last_status_rot = 0, n = 0, good = 0;
    for (const Sent &s : g_run.frames) {
        if (s.f.id == g_board->can_id_status) {
            assert_int_equal(planes[static_cast<size_t>(s.rotation)], 1); // the plane came first
            last_status_rot = s.rotation;
        }
        if (s.f.id != g_board->can_id_ground_plane) {
            continue;
        }
        assert_true(s.rotation > last_status_rot);
        planes[static_cast<size_t>(s.rotation)]++;
        const sl_can_e2e_status_t st = sl_can_e2e_check(&rx, e2e(SL_CAN_MSG_GROUND_PLANE), &s.f);
        assert_int_equal(st, n == 0 ? SL_CAN_E2E_INITIAL : SL_CAN_E2E_OK);
        sl_can_ground_plane_t g;
        assert_int_equal(sl_can_decode_ground_plane(&s.f, e2e(SL_CAN_MSG_GROUND_PLANE), &g), SL_OK);
        n++;
        if (g.quality == SL_CAN_GROUND_GOOD) {
            good++;
            // the radar 2.58 m over flat ground, the vehicle level on it (sim_ground_terrain
            // bounds the module; here the frames carry what it found)
            assert_true(std::fabs(g.height_mm * 1e-3 - g_run.height_m) <= 0.2);
            assert_true(std::abs(g.pitch_cdeg) <= 200);
            assert_true(std::abs(g.roll_cdeg) <= 50);
            assert_true(g.height_sigma_mm <= 20U + 5U);
            assert_true(g.pitch_sigma_cdeg <= 30U + 5U && g.roll_sigma_cdeg <= 30U + 5U);
        } else if (g.quality == SL_CAN_GROUND_NONE) {
            assert_int_equal(g.height_mm, 0);
        }
    }
    for (int k = 1; k <= g_run.rotations; k++) {
        assert_int_equal(planes[static_cast<size_t>(k)], 1);
    }
    assert_int_equal(n, g_run.rotations);
    assert_true(good >= g_run.rotations / 2);
}

// The drop-off ahead arrives as GroundHazard DROP frames: one per confirmed sector and
// rotation, right after the rotation's GroundPlane, never a STEP; the first DROP ahead lies
// within the ring (3-6 m out on paper-sim), 0.2 m lower within its sigma's reach.
static void test_ground_hazard_frames_carry_the_drop_off(void **)
{
    int drops_ahead = 0, hazards = 0, first_ahead_rot = -1;
    sl_can_e2e_rx_t rx;
    sl_can_e2e_rx_init(&rx, 1U);
    std::vector<int> per_rot(static_cast<size_t>(g_run.rotations) + 1, 0);
    bool after_plane = false;
    for (const Sent &s : g_run.frames) {
        if (s.f.id == g_board->can_id_ground_plane) {
            after_plane = true;
            continue;
        }
        if (s.f.id != g_board->can_id_ground_hazard) {
            after_plane = false;
            continue;
        }
        assert_true(after_plane); // hazards follow their plane without another frame between
        const sl_can_e2e_status_t st = sl_can_e2e_check(&rx, e2e(SL_CAN_MSG_GROUND_HAZARD), &s.f);
        assert_int_equal(st, hazards == 0 ? SL_CAN_E2E_INITIAL : SL_CAN_E2E_OK);
        sl_can_ground_hazard_t h;
        assert_int_equal(sl_can_decode_ground_hazard(&s.f, e2e(SL_CAN_MSG_GROUND_HAZARD), &h), SL_OK);
        hazards++;
        per_rot[static_cast<size_t>(s.rotation)]++;
        assert_int_equal(h.kind, SL_CAN_GROUND_DROP);
        assert_false(h.clamped);
        assert_true(h.sector < SL_CFG_GROUND_SECTORS);
        // a confirmed sector of the module in this rotation, its values on the signals' grid:
        // the ground above the plane (the module's residual is below it), the distance from
        // um, the sector's centre (HeightDiff is the last fit's: while a hazard holds
        // through its hysteresis it can lie inside the threshold)
        const sl_ground_sector_t &sec = g_run.sectors[static_cast<size_t>(s.rotation) - 1][h.sector];
        assert_int_equal(sec.kind, SL_GROUND_DROP);
        assert_int_equal(h.height_diff_mm, on_grid(-sec.resid_mm, SL_CAN_HAZARD_DIFF_MM_PER_LSB));
        assert_int_equal(h.sigma_mm, on_grid(sec.sigma_mm, SL_CAN_HAZARD_SIGMA_MM_PER_LSB));
        assert_int_equal(h.distance_um, on_grid(sec.dist_um, SL_CAN_HAZARD_DIST_UM_PER_LSB));
        assert_true(std::abs(h.azimuth_cdeg - sl_ground_sector_cdeg(&g_run.p->ground, h.sector)) <= 5);
        assert_true(h.sigma_mm > 0U && h.sigma_mm <= 100U);
        const int32_t off = std::abs(((h.azimuth_cdeg + 18000) % 36000) - 18000);
        if (off <= 4500) {
            drops_ahead++;
            if (first_ahead_rot < 0) {
                first_ahead_rot = s.rotation;
                std::printf("first DROP ahead: rotation %d sector %u az %.1f deg, %.3f m lower "
                            "(sigma %.3f m), %.2f m from the radar\n",
                            s.rotation - 1, h.sector, h.azimuth_cdeg * 0.01, -h.height_diff_mm * 1e-3,
                            h.sigma_mm * 1e-3, h.distance_um * 1e-6);
                // the dock's 0.2 m, within the ring (3-6 m on paper-sim) less the travel since
                assert_true(h.height_diff_mm <= -150 && h.height_diff_mm >= -300);
                assert_true(h.distance_um >= 500000U && h.distance_um <= 8000000U);
            }
        }
    }
    // exactly the confirmed sectors of each rotation went out
    for (int k = 1; k <= g_run.rotations; k++) {
        int confirmed = 0;
        for (const sl_ground_sector_t &sec : g_run.sectors[static_cast<size_t>(k) - 1]) {
            confirmed += sec.kind != SL_GROUND_FLAT ? 1 : 0;
        }
        assert_int_equal(per_rot[static_cast<size_t>(k)], confirmed);
    }
    std::printf("GroundHazard: %d frames, %d DROP ahead\n", hazards, drops_ahead);
    assert_true(drops_ahead > 0);
    assert_true(first_ahead_rot > 0);
    assert_int_equal(g_run.p->stats.can_rate_limited, 0);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_ground_plane_once_per_rotation_before_status),
        cmocka_unit_test(test_ground_hazard_frames_carry_the_drop_off),
    };
    return cmocka_run_group_tests(tests, setup, nullptr);
}
