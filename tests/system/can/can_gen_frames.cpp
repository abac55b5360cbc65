// SPDX-License-Identifier: MIT
// can_gen_frames: encode many random messages with the core's encoders for one board and
// write them as a candump log plus a list of the encoder INPUTS (physical integer units),
// so check_dbc_decode.py can decode the log with the generated DBC (python3-canmatrix)
// and compare every signal with what went in.
//
//   can_gen_frames BOARD N SEED OUT.log OUT.expect
//
// About 10 % of the values are outside their signal's range, to exercise clamping.
#include <cstdint>
#include <cstdio>
#include <fstream>
#include <iostream>
#include <random>
#include <string>

#include "candump_log.h"
#include "sl_board_spec.h"
#include "sl_dbc.h"
#include "shadowlean/sl_can.h"

namespace {

std::mt19937_64 rng;

int64_t uni(int64_t lo, int64_t hi)
{
    return std::uniform_int_distribution<int64_t>(lo, hi)(rng);
}

bool chance(int percent)
{
    return uni(0, 99) < percent;
}

// In range most of the time, sometimes far outside (both sides).
int64_t value(int64_t lo, int64_t hi, int64_t wild_lo, int64_t wild_hi)
{
    return chance(10) ? uni(wild_lo, wild_hi) : uni(lo, hi);
}

} // namespace

int main(int argc, char **argv)
{
    if (argc != 6) {
        std::cerr << "usage: can_gen_frames BOARD N SEED OUT.log OUT.expect\n";
        return 2;
    }
    try {
        const sl::BoardSpec b = sl::load_board(argv[1]);
        const long n = std::stol(argv[2]);
        rng.seed(std::stoull(argv[3]));
        const sl_can_ids_t ids = sl::can_ids(b);
        sl_can_tx_t tx;
        if (sl_can_tx_init(&tx, &ids) != SL_OK) {
            std::cerr << "can_gen_frames: bad ids\n";
            return 1;
        }
        sl::CandumpWriter log;
        log.open(argv[4], "can0");
        std::ofstream ex(argv[5]);
        uint64_t t_us = 1700000000000000ULL;
        for (long i = 0; i < n; i++) {
            sl_can_frame_t f;
            const int64_t kind = uni(0, 13);
            if (kind < 6) {
                sl_can_pole_lean_t p{};
                p.target_id = static_cast<uint8_t>(value(0, 15, 0, 255));
                p.quality = static_cast<uint8_t>(value(0, 4, 0, 255));
                p.azimuth_cdeg = static_cast<int32_t>(value(0, 35999, INT32_MIN, INT32_MAX));
                p.lean_cdeg = static_cast<int32_t>(value(-5000, 5000, -100000, 100000));
                p.lean_sigma_cdeg = static_cast<uint32_t>(value(0, 620, 0, 100000));
                p.range_inner_um = static_cast<uint32_t>(value(0, 10229999, 0, UINT32_MAX));
                p.range_outer_um = static_cast<uint32_t>(value(0, 10229999, 0, UINT32_MAX));
                sl_can_encode_pole_lean(&tx, &p, &f);
                ex << "PoleLean target_id=" << unsigned(p.target_id) << " quality=" << unsigned(p.quality)
                   << " azimuth_cdeg=" << p.azimuth_cdeg << " lean_cdeg=" << p.lean_cdeg
                   << " lean_sigma_cdeg=" << p.lean_sigma_cdeg << " range_inner_um=" << p.range_inner_um
                   << " range_outer_um=" << p.range_outer_um << "\n";
            } else if (kind < 8) {
                sl_can_lean_warning_t w{};
                w.level = static_cast<uint8_t>(value(0, 2, 0, 255));
                w.has_target = !chance(10);
                w.target_id = static_cast<uint8_t>(value(0, 15, 0, 255));
                w.quality = static_cast<uint8_t>(value(0, 4, 0, 255));
                w.azimuth_cdeg = static_cast<int32_t>(value(0, 35999, -1000000, 1000000));
                w.lean_cdeg = static_cast<int32_t>(value(-10240, 10235, -100000, 100000));
                w.range_um = static_cast<uint32_t>(value(0, 20474999, 0, 1000000000));
                w.lean_sigma_cdeg = static_cast<uint32_t>(value(0, 630, 0, 100000));
                sl_can_encode_lean_warning(&tx, &w, &f);
                ex << "LeanWarning level=" << unsigned(w.level) << " has_target=" << int(w.has_target)
                   << " target_id=" << unsigned(w.target_id) << " quality=" << unsigned(w.quality)
                   << " azimuth_cdeg=" << w.azimuth_cdeg << " lean_cdeg=" << w.lean_cdeg
                   << " range_um=" << w.range_um << " lean_sigma_cdeg=" << w.lean_sigma_cdeg << "\n";
            } else if (kind < 9) {
                sl_can_status_t s{};
                s.link_state = static_cast<uint8_t>(value(0, 4, 0, 255));
                s.rotations = static_cast<uint32_t>(value(0, 262143, 0, UINT32_MAX));
                s.azimuths_missing = static_cast<uint32_t>(value(0, 16383, 0, UINT32_MAX));
                s.decoder_resyncs = static_cast<uint32_t>(value(0, 255, 0, 100000));
                s.can_dropped = static_cast<uint32_t>(value(0, 255, 0, 100000));
                sl_can_encode_status(&tx, &s, &f);
                ex << "Status link_state=" << unsigned(s.link_state) << " rotations=" << s.rotations
                   << " azimuths_missing=" << s.azimuths_missing << " decoder_resyncs=" << s.decoder_resyncs
                   << " can_dropped=" << s.can_dropped << "\n";
            } else if (kind == 10) {
                sl_can_health_t h{};
                h.fault = static_cast<uint16_t>(value(0, 0x3FF, 0, 0xFFFF));
                h.reconnects = static_cast<uint32_t>(value(0, 255, 0, 100000));
                h.candidates_dropped = static_cast<uint32_t>(value(0, 4095, 0, 1000000));
                h.theta_drift_cdeg = static_cast<int16_t>(value(-1280, 1270, -30000, 30000));
                sl_can_encode_health(&tx, &h, &f);
                ex << "Health fault=" << unsigned(h.fault) << " reconnects=" << h.reconnects
                   << " candidates_dropped=" << h.candidates_dropped
                   << " theta_drift_cdeg=" << h.theta_drift_cdeg << "\n";
            } else if (kind == 11) {
                sl_can_pole_tilt_t t{};
                t.target_id = static_cast<uint8_t>(value(0, 15, 0, 255));
                t.quality = static_cast<uint8_t>(chance(70) ? uni(0, 1) : value(2, 4, 0, 255));
                t.tilt_cdeg = static_cast<int32_t>(value(0, 2550, 0, 100000));
                t.direction_cdeg = static_cast<int32_t>(value(0, 35999, -1000000, 1000000));
                t.tilt_sigma_cdeg = static_cast<uint32_t>(value(0, 620, 0, 100000));
                t.direction_sigma_cdeg = static_cast<uint32_t>(value(0, 6300, 0, 100000));
                t.base_x_um = static_cast<int32_t>(value(-6400000, 6350000, -100000000, 100000000));
                t.base_y_um = static_cast<int32_t>(value(-6400000, 6350000, -100000000, 100000000));
                sl_can_encode_pole_tilt(&tx, &t, &f);
                ex << "PoleTilt target_id=" << unsigned(t.target_id) << " quality=" << unsigned(t.quality)
                   << " tilt_cdeg=" << t.tilt_cdeg << " direction_cdeg=" << t.direction_cdeg
                   << " tilt_sigma_cdeg=" << t.tilt_sigma_cdeg
                   << " direction_sigma_cdeg=" << t.direction_sigma_cdeg << " base_x_um=" << t.base_x_um
                   << " base_y_um=" << t.base_y_um << "\n";
            } else if (kind == 12) {
                sl_can_ground_plane_t g{};
                g.quality = static_cast<uint8_t>(chance(80) ? uni(1, 2) : value(0, 0, 0, 255));
                g.height_mm = static_cast<int32_t>(value(0, 8190, -100000, 100000));
                g.pitch_cdeg = static_cast<int32_t>(value(-2048, 2046, -100000, 100000));
                g.roll_cdeg = static_cast<int32_t>(value(-2048, 2046, -100000, 100000));
                g.height_sigma_mm = static_cast<uint32_t>(value(0, 155, 0, 100000));
                g.pitch_sigma_cdeg = static_cast<uint32_t>(value(0, 155, 0, 100000));
                g.roll_sigma_cdeg = static_cast<uint32_t>(value(0, 155, 0, 100000));
                sl_can_encode_ground_plane(&tx, &g, &f);
                ex << "GroundPlane quality=" << unsigned(g.quality) << " height_mm=" << g.height_mm
                   << " pitch_cdeg=" << g.pitch_cdeg << " roll_cdeg=" << g.roll_cdeg
                   << " height_sigma_mm=" << g.height_sigma_mm << " pitch_sigma_cdeg=" << g.pitch_sigma_cdeg
                   << " roll_sigma_cdeg=" << g.roll_sigma_cdeg << "\n";
            } else if (kind == 13) {
                sl_can_ground_hazard_t h{};
                h.kind = static_cast<uint8_t>(chance(80) ? uni(1, 2) : value(0, 0, 0, 255));
                h.sector = static_cast<uint8_t>(value(0, 63, 0, 255));
                h.azimuth_cdeg = static_cast<int32_t>(value(0, 35999, -1000000, 1000000));
                h.height_diff_mm = static_cast<int32_t>(value(-5120, 5115, -100000, 100000));
                h.distance_um = static_cast<uint32_t>(value(0, 20474999, 0, UINT32_MAX));
                h.sigma_mm = static_cast<uint32_t>(value(0, 1275, 0, 100000));
                sl_can_encode_ground_hazard(&tx, &h, &f);
                ex << "GroundHazard kind=" << unsigned(h.kind) << " sector=" << unsigned(h.sector)
                   << " azimuth_cdeg=" << h.azimuth_cdeg << " height_diff_mm=" << h.height_diff_mm
                   << " distance_um=" << h.distance_um << " sigma_mm=" << h.sigma_mm << "\n";
            } else {
                sl_can_vehicle_motion_t m{};
                m.speed_mm_s = static_cast<int32_t>(value(-60000, 60000, -1000000, 1000000));
                m.yaw_rate_cdeg_s = static_cast<int32_t>(value(-20000, 20000, -100000, 100000));
                m.speed_valid = chance(90);
                m.yaw_rate_valid = chance(90);
                sl_can_encode_vehicle_motion(&tx, &m, &f);
                ex << "VehicleMotion speed_mm_s=" << m.speed_mm_s << " yaw_rate_cdeg_s=" << m.yaw_rate_cdeg_s
                   << " speed_valid=" << int(m.speed_valid) << " yaw_rate_valid=" << int(m.yaw_rate_valid)
                   << "\n";
            }
            if (log.write(f, t_us) != SL_OK) {
                std::cerr << "can_gen_frames: log write failed\n";
                return 1;
            }
            t_us += static_cast<uint64_t>(uni(1, 5000));
        }
        log.close();
        ex.close();
        if (!ex) {
            std::cerr << "can_gen_frames: cannot write " << argv[5] << "\n";
            return 1;
        }
        std::cout << "can_gen_frames: " << n << " frames, " << tx.stats.clamped_frames
                  << " with clamped values\n";
        return 0;
    } catch (const std::exception &e) {
        std::cerr << "can_gen_frames: " << e.what() << "\n";
        return 1;
    }
}
