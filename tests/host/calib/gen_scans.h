// SPDX-License-Identifier: MIT
// gen_scans.h: synthetic radar captures with KNOWN shadow and elongation, for the
// calibration tests (tests/host/calib) and the sl-view pictures. Written through the core's
// encoders (sl_proto_encode_config / sl_proto_encode_fft8), decoded by the tools like any
// capture. Deliberately independent of the scene simulator (sl-sim): a small forward model
// whose truth is a parameter, not a measurement.
//
// Per azimuth index i, rotation k, range bin j (bin j spans [j b, (j + 1) b)):
//   amplitude = | s(i, j, k) e^{i phi} + n |, n complex Gaussian (sigma per component), phi
//   uniform; 8-bit value = 0 if floor(amplitude) <= 1, else round(19.8 log10 floor(amplitude))
//   (the Navtech log quantisation of the Oxford data: 0, 6, 9, 12, 14, 15, 17, 18, ...;
//   sigma 1.6 gives ~55 % zeros in the dark ring, REAL_SCANS.md s.2).
// Signal terms s (amplitudes add in power):
//   - near-field leakage: `band_amp` to band_end_m, `shoulder_amp` to shoulder_end_m, a fixed
//     per-pixel pattern (+-band_jitter) that does not change over rotations;
//   - ground: beyond the slant shadow edge S(i) = sqrt(R(i)^2 + H^2), R(i) from the board
//     (BoardSpec::shadow_radius_m), amplitude ground_amp (S / r)^1.5 times a Rayleigh speckle
//     drawn per rotation, times sqrt(fraction of the bin beyond S) (partly lit bins);
//   - self-returns: platform-fixed bright patches (azimuth range, range interval, amplitude);
//   - a target: a thin vertical pole at horizontal distance p on azimuth az: a return from
//     r1 = p to r2 = p / cos(theta(az)) + d, d the elongation (smeared outward), amplitude
//     target_amp (neighbours +-1: target_side_amp), partly filled end bins scaled by
//     sqrt(fill).
#pragma once

#include <cstdint>
#include <string>
#include <utility>
#include <vector>

#include "sl_board_spec.h"

namespace sl::test {

struct SelfReturn {
    int az_first = 0, az_last = 0;  ///< inclusive azimuth indices
    double r0_m = 0, r1_m = 0;      ///< slant range interval
    double amp = 300;
};

struct Target {
    int az = 0;
    double p_m = 2.0;               ///< horizontal distance (= true r1)
    double d_m = 0.8;               ///< elongation of the outer bound
};

struct GenSpec {
    BoardSpec board;
    int rotations = 8;
    int bins = 200;                 ///< bins per FFT message
    uint64_t seed = 1;
    double noise_sigma = 1.6;
    double band_amp = 83, shoulder_amp = 9, band_end_m = 1.5, shoulder_end_m = 2.2;
    double band_jitter = 0.08;
    bool ground = true;
    double ground_amp = 40;
    std::vector<std::pair<int, int>> no_ground; ///< azimuth ranges (inclusive) with no ground
                                                ///< return (hidden by the platform)
    std::vector<SelfReturn> self_returns;
    std::vector<Target> targets;
    double target_amp = 2000, target_side_amp = 300;
};

/// The capture (Configuration + rotations x azimuths FFT messages, 8-bit).
std::vector<uint8_t> generate_capture(const GenSpec &g);

/// True slant shadow edge of azimuth i: sqrt(R^2 + H^2).
double true_slant_m(const BoardSpec &b, int i);

/// The outer bound a target's return ends at: p / cos(theta(az)) + d.
double target_r2_true_m(const BoardSpec &b, const Target &t);

/// Writes `bytes` to `path`; false on error.
bool write_file(const std::string &path, const std::vector<uint8_t> &bytes);

} // namespace sl::test
