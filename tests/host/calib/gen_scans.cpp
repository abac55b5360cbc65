// SPDX-License-Identifier: MIT
// gen_scans.cpp: see gen_scans.h.
#include "gen_scans.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstring>

#include "shadowlean/sl_proto.h"

namespace sl::test {
namespace {

constexpr double kPi = 3.14159265358979323846;

uint64_t mix(uint64_t a, uint64_t b, uint64_t c, uint64_t d)
{
    uint64_t h = a * 0x9E3779B97F4A7C15ULL ^ (b + 0x632BE59BD9B4E019ULL);
    h ^= (c + 0x85EBCA77C2B2AE63ULL) * 0xC2B2AE3D27D4EB4FULL;
    h ^= (d + 0x27D4EB2F165667C5ULL) * 0x165667B19E3779F9ULL;
    h ^= h >> 31;
    h *= 0xBF58476D1CE4E5B9ULL;
    h ^= h >> 29;
    return h;
}

/// splitmix64 stream: cheap, deterministic, good enough for test noise.
struct Rng {
    uint64_t s;
    uint64_t next()
    {
        uint64_t z = (s += 0x9E3779B97F4A7C15ULL);
        z = (z ^ (z >> 30)) * 0xBF58476D1CE4E5B9ULL;
        z = (z ^ (z >> 27)) * 0x94D049BB133111EBULL;
        return z ^ (z >> 31);
    }
    double uniform() { return (next() >> 11) * (1.0 / 9007199254740992.0); }
    double normal()
    {
        const double u1 = std::max(1e-300, uniform()), u2 = uniform();
        return std::sqrt(-2.0 * std::log(u1)) * std::cos(2 * kPi * u2);
    }
};

uint8_t quantise(double amplitude)
{
    const double n = std::floor(amplitude);
    if (n <= 1) {
        return 0;
    }
    const double v = std::round(19.8 * std::log10(n));
    return static_cast<uint8_t>(std::min(255.0, v));
}

/// Fraction of bin [j b, (j + 1) b) inside [lo, hi].
double overlap(int j, double b, double lo, double hi)
{
    const double a = std::max(lo, j * b), e = std::min(hi, (j + 1) * b);
    return std::max(0.0, e - a) / b;
}

} // namespace

double true_slant_m(const BoardSpec &b, int i)
{
    const double R = b.shadow_radius_m(i);
    return std::hypot(R, b.radar_height_m);
}

double target_r2_true_m(const BoardSpec &b, const Target &t)
{
    return t.p_m / std::cos(b.theta_deg(t.az) * kPi / 180.0);
}

std::vector<uint8_t> generate_capture(const GenSpec &g)
{
    const BoardSpec &b = g.board;
    const int A = b.azimuths, K = g.bins;
    const double bin = b.bin_size_m;
    std::vector<uint8_t> out;
    std::vector<uint8_t> buf(64 + static_cast<size_t>(K) + 64);
    sl_proto_config_t c{};
    c.azimuths = static_cast<uint16_t>(A);
    c.bin_size_100um = static_cast<uint16_t>(std::lround(bin * 10000));
    c.range_bins = static_cast<uint16_t>(K);
    c.encoder_size = static_cast<uint16_t>(b.encoder_size);
    c.rotation_mhz = 4000;
    c.packet_rate = static_cast<uint16_t>(A * 4);
    c.has_data_width = true;
    c.data_width = 1;
    // Exact bin size in the protobuf (float32 bit pattern of the board's metres).
    {
        const float f = static_cast<float>(bin);
        uint32_t u = 0;
        static_assert(sizeof f == sizeof u, "float32");
        std::memcpy(&u, &f, sizeof u);
        c.has_range_res = true;
        c.range_res_m_f32 = u;
    }
    std::vector<uint8_t> cfg(256);
    const sl_ssize_t n = sl_proto_encode_config(cfg.data(), cfg.size(), &c, sl_bytes_t{nullptr, 0});
    out.insert(out.end(), cfg.begin(), cfg.begin() + n);

    std::vector<double> slant(A);
    for (int i = 0; i < A; i++) {
        slant[i] = true_slant_m(b, i);
    }
    std::vector<uint8_t> row(K);
    uint16_t sweep = 0;
    for (int k = 0; k < g.rotations; k++) {
        for (int i = 0; i < A; i++) {
            Rng rng{mix(g.seed, static_cast<uint64_t>(k), static_cast<uint64_t>(i), 1)};
            for (int j = 0; j < K; j++) {
                const double r0 = j * bin, rc = (j + 0.5) * bin;
                double p = 0;
                // Near-field band: fixed pattern (seeded by azimuth and bin only).
                double band = 0;
                if (rc < g.band_end_m) {
                    band = g.band_amp;
                } else if (rc < g.shoulder_end_m) {
                    band = g.shoulder_amp;
                }
                if (band > 0) {
                    Rng fr{mix(g.seed, 0xBA4D, static_cast<uint64_t>(i), static_cast<uint64_t>(j))};
                    band *= 1.0 + g.band_jitter * (2 * fr.uniform() - 1);
                    p += band * band;
                }
                bool ground = g.ground;
                for (const auto &ng : g.no_ground) {
                    ground = ground && !(i >= ng.first && i <= ng.second);
                }
                if (ground) {
                    const double fill = overlap(j, bin, slant[i], 1e9);
                    if (fill > 0) {
                        const double a = g.ground_amp * std::pow(slant[i] / std::max(rc, slant[i]), 1.5);
                        const double sx = rng.normal(), sy = rng.normal();
                        const double speckle = std::sqrt(0.5 * (sx * sx + sy * sy));
                        p += a * a * speckle * speckle * fill;
                    }
                }
                for (const auto &sr : g.self_returns) {
                    if (i >= sr.az_first && i <= sr.az_last) {
                        const double f = overlap(j, bin, sr.r0_m, sr.r1_m);
                        p += sr.amp * sr.amp * f;
                    }
                }
                for (const auto &t : g.targets) {
                    const int da = std::abs(((i - t.az) % A + A + A / 2) % A - A / 2);
                    if (da > 1) {
                        continue;
                    }
                    const double amp = da == 0 ? g.target_amp : g.target_side_amp;
                    const double f = overlap(j, bin, t.p_m, target_r2_true_m(b, t) + t.d_m);
                    p += amp * amp * f;
                }
                (void)r0;
                const double s = std::sqrt(p), ph = 2 * kPi * rng.uniform();
                const double re = s * std::cos(ph) + g.noise_sigma * rng.normal();
                const double im = s * std::sin(ph) + g.noise_sigma * rng.normal();
                row[j] = quantise(std::hypot(re, im));
            }
            sl_proto_fft_t f{};
            f.id = SL_PROTO_ID_FFT_DATA;
            f.sweep_counter = sweep++;
            f.azimuth_ticks = static_cast<uint16_t>(std::lround(static_cast<double>(i) * b.encoder_size / A));
            const double t_s = 1700000000.0 + (k * A + i) / (4.0 * A);
            f.seconds = static_cast<uint32_t>(t_s);
            f.split_ns = static_cast<uint32_t>((t_s - std::floor(t_s)) * 1e9);
            f.bins = static_cast<uint32_t>(K);
            const sl_ssize_t m = sl_proto_encode_fft8(buf.data(), buf.size(), &f, row.data());
            out.insert(out.end(), buf.begin(), buf.begin() + m);
        }
    }
    return out;
}

bool write_file(const std::string &path, const std::vector<uint8_t> &bytes)
{
    std::FILE *f = std::fopen(path.c_str(), "wb");
    if (!f) {
        return false;
    }
    const bool ok = std::fwrite(bytes.data(), 1, bytes.size(), f) == bytes.size();
    return std::fclose(f) == 0 && ok;
}

} // namespace sl::test
