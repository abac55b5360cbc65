// SPDX-License-Identifier: MIT
// sim_render.cpp: see sim_render.h.
#include "sim_render.h"

#include <algorithm>
#include <atomic>
#include <condition_variable>
#include <cstring>
#include <mutex>
#include <thread>
#include <limits>

#include "shadowlean/sl_proto.h"
#include "shadowlean/sl_response.h"
#include "sl_geom.h"

namespace sl {

// ------------------------------------------------------------------------------------------
// random numbers

uint64_t sim_hash(uint64_t a, uint64_t b, uint64_t c, uint64_t d)
{
    auto mix = [](uint64_t z) {
        z += 0x9E3779B97F4A7C15ULL;
        z = (z ^ (z >> 30)) * 0xBF58476D1CE4E5B9ULL;
        z = (z ^ (z >> 27)) * 0x94D049BB133111EBULL;
        return z ^ (z >> 31);
    };
    uint64_t h = mix(a);
    h = mix(h ^ b);
    h = mix(h ^ (c * 0xD1B54A32D192ED03ULL));
    h = mix(h ^ (d * 0x8CB92BA72F3D8DD7ULL));
    return h;
}

double sim_uniform(uint64_t h) { return static_cast<double>(h >> 11) * (1.0 / 9007199254740992.0); }

double sim_normal(uint64_t h)
{
    const double u1 = 1.0 - sim_uniform(h);                   // (0, 1]
    const double u2 = sim_uniform(sim_hash(h, 0x5EED));
    return std::sqrt(-2.0 * std::log(u1)) * std::cos(2.0 * kSimPi * u2);
}

void sim_split_time(double unix_s, uint32_t *seconds, uint32_t *split_ns)
{
    double sec = std::floor(unix_s);
    long long ns = std::llround((unix_s - sec) * 1e9);
    if (ns >= 1000000000LL) {
        sec += 1;
        ns -= 1000000000LL;
    }
    *seconds = static_cast<uint32_t>(sec);
    *split_ns = static_cast<uint32_t>(ns);
}

void SimColumn::reset(int bins)
{
    energy.assign(static_cast<size_t>(bins), 0.0);
    peak.assign(static_cast<size_t>(bins), 0.0F);
    touched.assign(static_cast<size_t>(bins), 0);
    fine.clear();
    points.clear();
}

// ------------------------------------------------------------------------------------------

struct Simulator::PoleView {
    int pole = 0;
    RadarPose pose;
    VisibleAxis va;
    double az_off_deg = 0; ///< azimuth jitter of this rotation's azimuth (beam points off)
};

struct Simulator::RotationGeom {
    int k = 0;
    std::vector<std::vector<PoleView>> per_az;
    std::vector<GtRow> gt;
};

namespace {

constexpr uint64_t kSaltSpeckle = 0x5BEC1EULL, kSaltPhase = 0x9A5EULL, kSaltNoise = 0x4015EULL,
                   kSaltLeak = 0x1EA4ULL, kSaltClutter = 0xC1A77E4ULL, kSaltJitter = 0x717E5ULL,
                   kSaltFrame = 0xF4A3EULL, kSaltPhysBin = 0xB16C0DEULL,
                   kSaltPhysFine = 0xF16EC0DEULL;

void add_uniform(std::vector<double> &e, double bin, double a, double c, double E)
{
    if (E <= 0) {
        return;
    }
    if (c < a) {
        std::swap(a, c);
    }
    const long n = static_cast<long>(e.size());
    long ia = static_cast<long>(std::floor(a / bin));
    long ic = static_cast<long>(std::floor(c / bin));
    if (ic < 0 || ia >= n) {
        return;
    }
    if (ia == ic || c - a < 1e-15) {
        if (ia >= 0) {
            e[static_cast<size_t>(ia)] += E;
        }
        return;
    }
    const double inv = E / (c - a);
    for (long i = std::max(0L, ia); i <= std::min(ic, n - 1); i++) {
        const double lo = std::max(a, i * bin), hi = std::min(c, (i + 1) * bin);
        if (hi > lo) {
            e[static_cast<size_t>(i)] += (hi - lo) * inv;
        }
    }
}

// Integral of H(t) from 0 to q, where H is the probability that a ray hitting a circle of
// radius R_e (seen from afar) lands more than q R_e in front of the axis plane... i.e.
// P(hit range <= r_axis - q R_e) = H(q) = 1 (q <= 0), sqrt(1 - q^2) (0..1), 0 (q >= 1).
double Phi(double q)
{
    if (q <= 0) {
        return q;
    }
    if (q >= 1) {
        return 0.25 * kSimPi;
    }
    return 0.5 * (q * std::sqrt(1 - q * q) + std::asin(q));
}

double sinc(double x)
{
    if (std::fabs(x) < 1e-12) {
        return 1.0;
    }
    return std::sin(kSimPi * x) / (kSimPi * x);
}

} // namespace

double sim_window_amplitude(RangeResponse w, double f)
{
    double a0 = 1, a1 = 0, a2 = 0;
    switch (w) {
    case RangeResponse::Hann: a0 = 0.5; a1 = 0.5; break;
    case RangeResponse::Hamming: a0 = 0.54; a1 = 0.46; break;
    case RangeResponse::Blackman: a0 = 0.42; a1 = 0.5; a2 = 0.08; break;
    default: break;
    }
    // w[n] = a0 - a1 cos(2 pi n / N) + a2 cos(4 pi n / N): its transform is a sum of sincs
    // one resolution cell apart
    const double v = a0 * sinc(f) + 0.5 * a1 * (sinc(f - 1) + sinc(f + 1)) +
                     0.5 * a2 * (sinc(f - 2) + sinc(f + 2));
    return v / a0;
}

double sim_knife_edge_field(double v)
{
    constexpr double kMax = 12.0, kStep = 0.001;
    static const std::vector<double> table = [] {
        // C(v), S(v) by Simpson's rule from 0, then |F| = sqrt(((1/2 - C)^2 + (1/2 - S)^2) / 2)
        const int n = static_cast<int>(std::lround(kMax / kStep));
        std::vector<double> c(static_cast<size_t>(n) + 1, 0.0), sn(static_cast<size_t>(n) + 1, 0.0);
        for (int k = 1; k <= n; k++) {
            const double t0 = (k - 1) * kStep, t1 = k * kStep, tm = 0.5 * (t0 + t1);
            auto fc = [](double t) { return std::cos(0.5 * kSimPi * t * t); };
            auto fs = [](double t) { return std::sin(0.5 * kSimPi * t * t); };
            c[static_cast<size_t>(k)] = c[static_cast<size_t>(k) - 1] + (fc(t0) + 4 * fc(tm) + fc(t1)) / 6 * kStep;
            sn[static_cast<size_t>(k)] = sn[static_cast<size_t>(k) - 1] + (fs(t0) + 4 * fs(tm) + fs(t1)) / 6 * kStep;
        }
        std::vector<double> f(2 * static_cast<size_t>(n) + 1);
        for (int k = -n; k <= n; k++) {
            const double sg = k < 0 ? -1.0 : 1.0; // C and S are odd
            const double cc = sg * c[static_cast<size_t>(std::abs(k))];
            const double ss = sg * sn[static_cast<size_t>(std::abs(k))];
            f[static_cast<size_t>(k + n)] =
                std::sqrt(0.5 * ((0.5 - cc) * (0.5 - cc) + (0.5 - ss) * (0.5 - ss)));
        }
        return f;
    }();
    if (v >= kMax) {
        return 1.0 / (kSimPi * std::sqrt(2.0) * v);
    }
    if (v <= -kMax) {
        return 1.0;
    }
    const double u = (v + kMax) / kStep;
    const size_t j = std::min(table.size() - 2, static_cast<size_t>(u));
    const double fr = u - static_cast<double>(j);
    return table[j] + fr * (table[j + 1] - table[j]);
}

void sim_splat_profile(std::vector<double> &e, double bin, double a, double c, double re, double E,
                       int first_bin)
{
    if (E <= 0) {
        return;
    }
    if (re < 1e-9) {
        // sharp: uniform over [a, c]
        if (c < a) {
            std::swap(a, c);
        }
        const long n = static_cast<long>(e.size());
        const long ia = static_cast<long>(std::floor(a / bin)) - first_bin;
        const long ic = static_cast<long>(std::floor(c / bin)) - first_bin;
        if (ic < 0 || ia >= n) {
            return;
        }
        if (ia == ic || c - a < 1e-15) {
            if (ia >= 0) {
                e[static_cast<size_t>(ia)] += E;
            }
            return;
        }
        const double inv = E / (c - a);
        for (long i = std::max(0L, ia); i <= std::min(ic, n - 1); i++) {
            const double lo = std::max(a, (i + first_bin) * bin), hi = std::min(c, (i + first_bin + 1) * bin);
            if (hi > lo) {
                e[static_cast<size_t>(i)] += (hi - lo) * inv;
            }
        }
        return;
    }
    if (c < a) {
        std::swap(a, c);
    }
    // P(hit <= x) for an axis point at r: H((r - x) / re). Over r uniform in [a, c]:
    // mean of H = re / (c - a) * [Phi((c - x)/re) - Phi((a - x)/re)].
    const bool point = c - a < 1e-12;
    auto cdf = [&](double x) {
        if (point) {
            const double q = (a - x) / re;
            return q <= 0 ? 1.0 : (q >= 1 ? 0.0 : std::sqrt(1 - q * q));
        }
        return re / (c - a) * (Phi((c - x) / re) - Phi((a - x) / re));
    };
    const long n = static_cast<long>(e.size());
    const long ia = static_cast<long>(std::floor((a - re) / bin)) - first_bin;
    const long ic = static_cast<long>(std::floor(c / bin)) - first_bin;
    if (ic < 0 || ia >= n) {
        return;
    }
    double prev = cdf((std::max(0L, ia) + first_bin) * bin);
    for (long i = std::max(0L, ia); i <= std::min(ic, n - 1); i++) {
        const double next = cdf((i + first_bin + 1) * bin);
        e[static_cast<size_t>(i)] += E * std::max(0.0, next - prev);
        prev = next;
    }
}

namespace {

void touch(SimColumn &col, double bin, double a, double c, float pk)
{
    if (c < a) {
        std::swap(a, c);
    }
    const long n = static_cast<long>(col.touched.size());
    const long ia = std::max(0L, static_cast<long>(std::floor(a / bin)));
    const long ic = std::min(n - 1, static_cast<long>(std::floor(c / bin)));
    for (long i = ia; i <= ic; i++) {
        col.touched[static_cast<size_t>(i)] = 1;
        col.peak[static_cast<size_t>(i)] = std::max(col.peak[static_cast<size_t>(i)], pk);
    }
}

} // namespace

Simulator::Simulator(const Scene &scene) : s_(scene)
{
    validate_scene(s_);
    const BoardSpec &b = s_.board;
    for (const auto &p : s_.poles) {
        poles_.push_back(make_pole_geom(p));
    }
    for (const auto &x : s_.boxes) {
        boxes_.push_back(make_box_geom(x));
    }
    for (int i = 0; i < b.azimuths; i++) {
        az_deg_.push_back(b.azimuth_vehicle_deg(i));
        theta_deg_.push_back(b.theta_deg(i));
    }
    sigma_az_ = scene_az_sigma_deg(s_);
    cut_az_ = scene_az_cutoff_deg(s_);

    // ground: cumulative gain over depression
    const int nc = static_cast<int>(std::lround(90.0 / ground_cum_step_)) + 1;
    ground_cum_.assign(static_cast<size_t>(nc), 0.0);
    auto f = [&](double x) {
        return elevation_gain(-x) *
               (s_.ground_ambient + (1.0 - s_.ground_ambient) * std::sin(sim_d2r(x)));
    };
    for (int n = 1; n < nc; n++) {
        const double x0 = (n - 1) * ground_cum_step_, x1 = n * ground_cum_step_;
        ground_cum_[static_cast<size_t>(n)] =
            ground_cum_[static_cast<size_t>(n) - 1] +
            (f(x0) + 4 * f(0.5 * (x0 + x1)) + f(x1)) / 6.0 * ground_cum_step_;
    }
    if (s_.ground && scene_terrain(s_)) {
        terrain_moving_ = s_.speed_mps != 0.0 || s_.yaw_rate_dps != 0.0;
        if (!terrain_moving_) {
            const RadarPose pose = radar_pose_at(s_, 0.0);
            ground_cols_.resize(static_cast<size_t>(b.azimuths));
            for (int i = 0; i < b.azimuths; i++) {
                SimColumn c;
                c.reset(bins());
                ground_terrain(pose, i, c);
                ground_cols_[static_cast<size_t>(i)] = c.energy;
            }
        }
    } else if (s_.ground) {
        const int ncols = b.chassis_type == "cylinder" ? 1 : b.azimuths;
        ground_cols_.resize(static_cast<size_t>(ncols));
        for (int i = 0; i < ncols; i++) {
            SimColumn c;
            c.reset(bins());
            ground_analytic(i, c);
            ground_cols_[static_cast<size_t>(i)] = c.energy;
        }
    }

    // smear kernel: mode weight 1 at offset 0, front part = mode_frac of the width
    if (s_.smear && s_.smear_shape != 2) {
        const int W = std::max(1, static_cast<int>(std::lround(s_.smear_width_bins)));
        const int F = std::min(W - 1, static_cast<int>(std::lround(W * s_.smear_mode_frac)));
        smear_front_ = F;
        for (int j = -F; j < W - F; j++) {
            double k = 0;
            if (s_.smear_shape == 3) {
                // Gaussian over the window: sigma = W / 6 (the window holds +-3 sigma of a
                // centred kernel), truncated where the window ends
                const double sg = W / 6.0;
                k = std::exp(-0.5 * (j / sg) * (j / sg));
            } else if (s_.smear_shape == 4) {
                // Maxwell-Boltzmann density x^2 exp(-x^2 / (2 a^2)), x = j + F from the
                // window's start, its mode (a sqrt 2) at the target: a = max(F, 1) / sqrt 2
                const double x = j + F + 0.0, m = std::max(F, 1);
                k = (x / m) * (x / m) * std::exp(1.0 - (x / m) * (x / m));
            } else if (j <= 0) {
                k = (j + F + 1.0) / (F + 1.0);
            } else if (s_.smear_shape == 5) {
                // power law: (1 + j)^-p, the first bin down by decay_db (p = decay_db / 3.01):
                // steep next to the target, ever slower behind it (no single exponential)
                k = std::pow(1.0 + j, -s_.smear_decay_db / (10.0 * std::log10(2.0)));
            } else if (s_.smear_shape == 0) {
                k = 1.0 - static_cast<double>(j) / (W - F);
            } else {
                k = std::pow(10.0, -0.1 * s_.smear_decay_db * j);
            }
            smear_kernel_.push_back(k);
        }
    }

    // range response: the power R(o) a point return puts at offset o bins (1 at 0)
    if (scene_physical_response(s_)) {
        std::vector<double> taps; // cts350x: R at integer offsets
        int half = 0;
        if (s_.range_response == RangeResponse::None) {
            resp_delta_ = true;
        } else if (s_.range_response == RangeResponse::Cts350x) {
            uint16_t drop[SL_RESP_TAPS];
            sl_response_prior_cts350x(drop); // the core's table: one source of truth
            // the table's +-SL_CFG_RESP_HALF taps; with a skirt, beyond them the lobe falls on
            // at the slope of its last two taps for range_skirt_bins more
            half = SL_CFG_RESP_HALF + static_cast<int>(std::lround(s_.range_skirt_bins));
            for (int t = 0; t < SL_RESP_TAPS; t++) {
                taps.push_back(std::pow(2.0, -drop[t] / 256.0));
            }
        } else {
            half = std::min(64, std::max(20, static_cast<int>(std::ceil(7.0 * s_.range_cell_bins))));
        }
        const bool tail = s_.receiver_tail_bins > 0;
        const double tail0 = tail ? std::pow(10.0, 0.1 * s_.receiver_tail_db) : 0.0;
        int rhalf = half;
        if (tail && !resp_delta_) {
            // the tail down to -80 dB
            const double o80 = s_.receiver_tail_bins * std::log(10.0) * 0.1 * (s_.receiver_tail_db + 80.0);
            rhalf = std::max(half, std::min(200, static_cast<int>(std::ceil(o80))));
        }
        resp_half_ = resp_delta_ ? 0 : rhalf;
        const int nt = 2 * resp_half_ * kRespSub + 1;
        resp_pow_.assign(static_cast<size_t>(nt), 0.0);
        resp_amp_.assign(static_cast<size_t>(nt), 0.0);
        for (int t = 0; t < nt && !resp_delta_; t++) {
            const double o = static_cast<double>(t - resp_half_ * kRespSub) / kRespSub;
            double R = 0;
            if (s_.range_response == RangeResponse::Cts350x) {
                if (std::fabs(o) <= half) {
                    // a smooth lobe through the taps: Catmull-Rom on the drops (log power)
                    const long nt = static_cast<long>(taps.size());
                    const double u = o + SL_CFG_RESP_HALF;
                    const long j = static_cast<long>(std::floor(u));
                    const double t = u - static_cast<double>(j);
                    auto D = [&](long q) {
                        if (q < 0) {
                            return std::log2(taps[0]) + static_cast<double>(-q) *
                                                            (std::log2(taps[0]) - std::log2(taps[1]));
                        }
                        if (q >= nt) {
                            return std::log2(taps[static_cast<size_t>(nt - 1)]) +
                                   static_cast<double>(q - nt + 1) *
                                       (std::log2(taps[static_cast<size_t>(nt - 1)]) -
                                        std::log2(taps[static_cast<size_t>(nt - 2)]));
                        }
                        return std::log2(taps[static_cast<size_t>(q)]);
                    };
                    const double p0 = D(j - 1), p1 = D(j), p2 = D(j + 1), p3 = D(j + 2);
                    const double l = 0.5 * ((2 * p1) + (-p0 + p2) * t + (2 * p0 - 5 * p1 + 4 * p2 - p3) * t * t +
                                            (-p0 + 3 * p1 - 3 * p2 + p3) * t * t * t);
                    R = std::min(1.0, std::exp2(l));
                }
            } else if (std::fabs(o) <= half) {
                const double w = sim_window_amplitude(s_.range_response, o / s_.range_cell_bins);
                R = w * w;
            }
            if (tail && o > 0) {
                R += tail0 * std::exp(-o / s_.receiver_tail_bins);
            }
            resp_pow_[static_cast<size_t>(t)] = R;
            resp_amp_[static_cast<size_t>(t)] = std::sqrt(R);
        }
    }

    // pure noise: N = round(|n|) (magnitude) or round(|n|^2) (power, output.log_quantity), n
    // complex Gaussian, sigma per component
    if (s_.noise) {
        const double sg = std::max(1e-9, s_.noise_sigma);
        // |n| is Rayleigh, |n|^2 exponential (mean 2 sg^2)
        auto F = [&](double x) {
            return x <= 0 ? 0.0
                          : 1.0 - std::exp(-(s_.log_power ? x : x * x) / (2 * sg * sg));
        };
        for (int m = 0;; m++) {
            noise_cdf_.push_back(F(m + 0.5));
            const double v = log_value(m);
            noise_val_.push_back(static_cast<uint8_t>(std::min(255.0, v)));
            if (1.0 - noise_cdf_.back() < 1e-15 || m > 100000) {
                noise_cdf_.back() = 1.0;
                break;
            }
        }
    }

    // static scene: the geometry never changes; compute it once
    if (s_.speed_mps == 0.0 && s_.yaw_rate_dps == 0.0 && s_.az_jitter_deg == 0.0) {
        RotationGeom rg;
        rotation_geom(0, rg);
        static_cols_.resize(static_cast<size_t>(b.azimuths));
        for (int i = 0; i < b.azimuths; i++) {
            column_from(rg, i, static_cols_[static_cast<size_t>(i)]);
        }
    }
    deterministic_ = !s_.noise && (!s_.speckle || (scene_speckle_static(s_) && s_.speckle_frame_db == 0.0)) &&
                     (s_.points.empty() || !static_cols_.empty());
    if (deterministic_) {
        out_cache_.resize(static_cast<size_t>(b.azimuths));
        SimColumn col;
        for (int i = 0; i < b.azimuths; i++) {
            auto &o = out_cache_[static_cast<size_t>(i)];
            o.resize(static_cast<size_t>(bins()));
            if (!static_cols_.empty()) {
                map_column(0, i, static_cols_[static_cast<size_t>(i)], o.data());
            } else {
                RotationGeom none;
                none.k = 0;
                none.per_az.assign(static_cast<size_t>(b.azimuths), {});
                col.reset(bins());
                if (s_.ground && !ground_cols_.empty()) {
                    column_from(none, i, col);
                }
                map_column(0, i, col, o.data());
            }
        }
    }
}

Simulator::~Simulator() = default;

double Simulator::time_of(int k, int i) const
{
    return (k + static_cast<double>(i) / s_.board.azimuths) / s_.rotation_hz;
}

uint16_t Simulator::ticks_of(int i) const
{
    return static_cast<uint16_t>(
        std::lround(static_cast<double>(i) * s_.board.encoder_size / s_.board.azimuths) %
        s_.board.encoder_size);
}

double sim_elevation_gain(const Scene &s, double e)
{
    if (e > s.elev_top_deg || e < s.elev_bottom_deg) {
        return 0.0;
    }
    if (s.elevation == ElevationProfile::Ideal) {
        return 1.0;
    }
    const double pk = s.measured_peak_deg;
    const double u = e >= pk ? (e - pk) / (s.elev_top_deg - pk) : (pk - e) / (pk - s.elev_bottom_deg);
    return std::pow(10.0, -0.1 * s.measured_edge_db * u * u);
}

double Simulator::elevation_gain(double e) const { return sim_elevation_gain(s_, e); }

double Simulator::azimuth_gain(double d) const
{
    if (std::fabs(d) > cut_az_) {
        return 0.0;
    }
    return std::exp(-0.5 * d * d / (sigma_az_ * sigma_az_));
}

double Simulator::log_value(long n) const
{
    if (n <= 1) {
        return 0.0;
    }
    if (!s_.log_navtech) {
        return std::round(s_.log_db_per_decade * std::log10(static_cast<double>(n)));
    }
    // Navtech: N = 2^e (1 + m), value = round(cpo (e + m)), exact at powers of two
    int e = 0;
    while (e < 62 && (2L << e) <= n) {
        e++;
    }
    const double m = static_cast<double>(n) / static_cast<double>(1L << e) - 1.0;
    return std::round(s_.log_db_per_decade * std::log10(2.0) * (e + m));
}

double Simulator::range_response(double o) const
{
    if (resp_pow_.empty()) {
        return resp_delta_ && std::fabs(o) < 0.5 ? 1.0 : 0.0;
    }
    const double u = (o + resp_half_) * kRespSub;
    if (u < 0 || u > static_cast<double>(resp_pow_.size() - 1)) {
        return 0.0;
    }
    const size_t j = std::min(resp_pow_.size() - 2, static_cast<size_t>(u));
    const double fr = u - static_cast<double>(j);
    return resp_pow_[j] + fr * (resp_pow_[j + 1] - resp_pow_[j]);
}

double Simulator::knife_edge_gain(double az_deg, double e_deg, double r_m) const
{
    if (!s_.knife_edge) {
        return 1.0;
    }
    double t = 0;
    const double th = chassis_theta_deg(s_.board, az_deg, &t);
    if (!std::isfinite(th) || !(t > 0)) {
        return 1.0;
    }
    const double d1 = t / std::cos(sim_d2r(th)), d2 = r_m - d1;
    if (d2 <= 1e-6) {
        return 1.0;
    }
    const double lambda = 0.299792458 / s_.carrier_ghz;
    // diffraction angle: how far below the ray over the edge (> 0: in the geometric shadow)
    const double v = sim_d2r(-th - e_deg) * std::sqrt(2.0 * d1 * d2 / (lambda * (d1 + d2)));
    const double f = sim_knife_edge_field(v);
    return f * f * f * f; // two-way: out and back over the edge
}

void Simulator::add_points(int k, int i, const RadarPose &pose, SimColumn &col) const
{
    (void)k;
    const double a_c = az_deg_[static_cast<size_t>(i)];
    for (const auto &p : s_.points) {
        const V3 P{p.x_m, p.y_m, p.z_m};
        const V3 rel = P - pose.o;
        const double rr = norm(rel);
        if (rr < 1e-6) {
            continue;
        }
        const double e = sim_r2d(std::atan2(rel.z, std::hypot(rel.x, rel.y)));
        const double az = azimuth_of(pose, P);
        double g = elevation_gain(e) * azimuth_gain(wrap180(az - a_c));
        if (g <= 0) {
            continue;
        }
        if (s_.knife_edge) {
            g *= knife_edge_gain(az, e, rr);
        } else {
            const double th = chassis_theta_deg(s_.board, az);
            if (!(e >= -th)) {
                continue; // in the chassis shadow
            }
        }
        const double x = rr / bin_m();
        col.points.push_back({x, p.energy * g, rr});
        const long j = static_cast<long>(std::floor(x));
        if (j >= 0 && j < static_cast<long>(col.touched.size())) {
            col.touched[static_cast<size_t>(j)] = 1;
        }
    }
}

std::vector<uint8_t> Simulator::config_message() const
{
    const BoardSpec &b = s_.board;
    sl_proto_config_t c;
    std::memset(&c, 0, sizeof c);
    c.azimuths = static_cast<uint16_t>(b.azimuths);
    c.bin_size_100um = static_cast<uint16_t>(std::lround(b.bin_size_m * 1e4));
    c.range_bins = static_cast<uint16_t>(b.range_bins);
    c.encoder_size = static_cast<uint16_t>(b.encoder_size);
    c.rotation_mhz = static_cast<uint16_t>(std::lround(s_.rotation_hz * 1000));
    c.packet_rate = static_cast<uint16_t>(std::lround(b.azimuths * s_.rotation_hz));
    const float one = 1.0F, zero = 0.0F, res = static_cast<float>(b.bin_size_m);
    std::memcpy(&c.range_gain_f32, &one, 4);
    std::memcpy(&c.range_offset_f32, &zero, 4);
    c.has_data_width = true;
    c.data_width = 1;
    c.has_range_res = true;
    std::memcpy(&c.range_res_m_f32, &res, 4);
    std::vector<uint8_t> buf(256);
    const sl_bytes_t none = {nullptr, 0};
    const sl_ssize_t n = sl_proto_encode_config(buf.data(), buf.size(), &c, none);
    if (n <= 0) {
        throw SceneError("sl_proto_encode_config failed");
    }
    buf.resize(static_cast<size_t>(n));
    return buf;
}

// ------------------------------------------------------------------------------------------
// geometry of one rotation: which poles are visible on which azimuths, and the truth

void Simulator::rotation_geom(int k, RotationGeom &rg) const
{
    const BoardSpec &b = s_.board;
    const int N = b.azimuths;
    const double step = 360.0 / N;
    rg.k = k;
    rg.per_az.assign(static_cast<size_t>(N), {});
    rg.gt.clear();
    Occluders occ{&poles_, &boxes_};
    const Wedge w{s_.elev_top_deg, s_.elev_bottom_deg};
    auto index_of = [&](double az) {
        long i = std::lround((az - b.radar_yaw_deg) / step);
        i %= N;
        if (i < 0) {
            i += N;
        }
        return static_cast<int>(i);
    };
    for (size_t p = 0; p < poles_.size(); p++) {
        const PoleGeom &pg = poles_[p];
        const int self = static_cast<int>(p);
        // nominal azimuth: nearest to the midpoint of the wedge-visible axis (2 passes so
        // the pose is that of the nominal azimuth's own instant)
        RadarPose pose = radar_pose_at(s_, time_of(k, 0));
        VisibleAxis va0;
        int i_nom = -1;
        for (int pass = 0; pass < 3; pass++) {
            va0 = visible_axis(b, pose, pg, self, occ, w, 0, -1, 96);
            if (va0.runs == 0) {
                break;
            }
            const V3 mid = pg.at(0.5 * (va0.s_lo + va0.s_hi));
            i_nom = index_of(azimuth_of(pose, mid));
            pose = radar_pose_at(s_, time_of(k, i_nom));
        }
        if (va0.runs == 0 || i_nom < 0) {
            continue;
        }
        // angular spread of the visible axis around the nominal azimuth
        double lo = 0, hi = 0;
        for (int q = 0; q <= 16; q++) {
            const V3 P = pg.at(va0.s_lo + (va0.s_hi - va0.s_lo) * q / 16.0);
            const double d = wrap180(azimuth_of(pose, P) - az_deg_[static_cast<size_t>(i_nom)]);
            lo = std::min(lo, d);
            hi = std::max(hi, d);
        }
        const double h_min = std::max(1e-3, std::hypot(pg.at(va0.s_lo).x - pose.o.x,
                                                       pg.at(va0.s_lo).y - pose.o.y) - pg.radius);
        const double ang_r = sim_r2d(std::asin(std::min(1.0, pg.radius / h_min)));
        const int m_lo = static_cast<int>(std::ceil((-lo + cut_az_ + ang_r) / step)) + 1;
        const int m_hi = static_cast<int>(std::ceil((hi + cut_az_ + ang_r) / step)) + 1;
        for (int m = -std::min(m_lo, N / 2); m <= std::min(m_hi, N / 2 - 1); m++) {
            const int j = ((i_nom + m) % N + N) % N;
            PoleView pv;
            pv.pole = self;
            pv.pose = radar_pose_at(s_, time_of(k, j));
            pv.va = visible_axis(b, pv.pose, pg, self, occ, w, az_deg_[static_cast<size_t>(j)],
                                 cut_az_, 128);
            if (s_.az_jitter_deg > 0) {
                pv.az_off_deg = s_.az_jitter_deg *
                                (2.0 * sim_uniform(sim_hash(s_.seed, kSaltJitter, static_cast<uint64_t>(k),
                                                            static_cast<uint64_t>(j))) -
                                 1.0);
            }
            if (pv.va.runs == 0) {
                continue;
            }
            GtRow g;
            g.rotation = k;
            g.azimuth = j;
            g.nominal = j == i_nom ? 1 : 0;
            g.pole = self;
            g.pole_name = s_.poles[p].name;
            g.t_s = s_.start_time_s + time_of(k, j);
            g.radar_x_m = pv.pose.o.x;
            g.radar_y_m = pv.pose.o.y;
            g.heading_deg = pv.pose.heading_deg;
            g.az_center_deg = az_deg_[static_cast<size_t>(j)];
            const V3 mid = pg.at(0.5 * (pv.va.s_lo + pv.va.s_hi));
            g.bearing_deg = azimuth_of(pv.pose, mid);
            g.theta_deg = theta_deg_[static_cast<size_t>(j)];
            g.beta_deg = s_.elev_top_deg;
            g.r1_m = pv.va.r1;
            g.r2_m = pv.va.r2;
            splat_pole(pv, j, nullptr, &g.r1_surf_m, &g.r2_surf_m);
            g.r1_end = pv.va.r1_at_foot ? "foot" : seg_end_name(pv.va.r1_end);
            g.r2_end = seg_end_name(pv.va.r2_end);
            g.runs = pv.va.runs;
            g.valid = (pv.va.runs == 1 && (g.r1_end == "top" || g.r1_end == "foot") &&
                       g.r2_end == "wedge")
                          ? 1
                          : 0;
            const double bw_mid = sim_r2d(std::atan2(mid.y - pv.pose.o.y, mid.x - pv.pose.o.x));
            g.alpha_deg = inplane_alpha_deg(pg, bw_mid);
            g.alpha_az_deg = inplane_alpha_deg(pg, pv.pose.heading_deg - g.az_center_deg);
            int flag = 0;
            g.alpha_model_deg = alpha_oracle_deg(g.r1_m, g.r2_m, g.theta_deg, g.beta_deg, &flag);
            g.alpha_paper_deg = paper_alpha_gt_deg(pg, pv.pose);
            g.psi_deg = s_.poles[p].tilt_deg;
            g.phi_deg = wrap180(s_.poles[p].lean_deg - pv.pose.heading_deg);
            const double sh = std::min(pg.length, pv.pose.o.z / pg.v.z);
            const V3 ph = pg.at(sh);
            const double hh = sim_d2r(pv.pose.heading_deg);
            g.offset_m = -(ph.x - pv.pose.o.x) * std::sin(hh) + (ph.y - pv.pose.o.y) * std::cos(hh);
            g.along_m = (pv.pose.o.x - ph.x) * std::cos(hh) + (pv.pose.o.y - ph.y) * std::sin(hh);
            g.radius_m = pg.radius;
            rg.gt.push_back(g);
            rg.per_az[static_cast<size_t>(j)].push_back(std::move(pv));
        }
    }
}

std::vector<GtRow> Simulator::truth(int k) const
{
    RotationGeom rg;
    rotation_geom(k, rg);
    return rg.gt;
}

// ------------------------------------------------------------------------------------------
// objects -> energies

void Simulator::splat_pole(const PoleView &pv, int i, SimColumn *col, double *r1s,
                           double *r2s) const
{
    const PoleGeom &pg = poles_[static_cast<size_t>(pv.pole)];
    const RadarPose &r = pv.pose;
    const double bin = bin_m();
    const double a_c = az_deg_[static_cast<size_t>(i)] + pv.az_off_deg;
    const ScenePole &sp = s_.poles[static_cast<size_t>(pv.pole)];
    auto seg = [&sp](double s) {
        if (sp.segment_m <= 0) {
            return 1.0;
        }
        const double u = s - sp.segment_m * std::floor(s / sp.segment_m);
        return u < sp.segment_fill_m ? 1.0 : sp.segment_gap;
    };
    const double s_foot = dot(r.o - pg.base, pg.v);
    double r1 = std::numeric_limits<double>::infinity(), r2 = 0;
    struct Smp {
        double r, re, e, eps, g;
    };
    std::vector<Smp> sm;
    std::vector<double> ss;
    const bool ke = s_.knife_edge && col != nullptr;
    const bool fine = scene_physical_response(s_) && col != nullptr;
    auto ke_at = [&](double s) {
        const V3 P = pg.at(s);
        const V3 rel = P - r.o;
        return knife_edge_gain(azimuth_of(r, P), sim_r2d(std::atan2(rel.z, std::hypot(rel.x, rel.y))),
                               norm(rel));
    };
    // knife-edge diffraction: a run cut by the chassis ray goes on into the geometric
    // shadow until the two-way loss passes 60 dB (the truth's r1, r2 stay geometric)
    std::vector<std::pair<double, double>> runs = pv.va.run;
    std::vector<std::pair<double, double>> geo = pv.va.run;
    if (ke) {
        for (size_t q = 0; q < runs.size(); q++) {
            const double ds = std::max(1e-4, sim_d2r(s_.pole_step_deg) *
                                                 norm(pg.at(runs[q].first) - r.o));
            if (pv.va.ends[q].first == SegEnd::Chassis) {
                double sx = runs[q].first;
                for (int it = 0; it < 100000 && sx > 0 && ke_at(sx) > 1e-6; it++) {
                    sx = std::max(0.0, sx - ds);
                }
                runs[q].first = sx;
            }
            if (pv.va.ends[q].second == SegEnd::Chassis) {
                double sx = runs[q].second;
                for (int it = 0; it < 100000 && sx < pg.length && ke_at(sx) > 1e-6; it++) {
                    sx = std::min(pg.length, sx + ds);
                }
                runs[q].second = sx;
            }
        }
    }
    for (size_t rq = 0; rq < runs.size(); rq++) {
        const double s0 = runs[rq].first, s1 = runs[rq].second;
        auto elev = [&](double s) {
            const V3 d = pg.at(s) - r.o;
            return sim_r2d(std::atan2(d.z, std::hypot(d.x, d.y)));
        };
        const double de = std::fabs(elev(s1) - elev(s0));
        const int n = std::max(2, static_cast<int>(std::ceil(de / s_.pole_step_deg)) + 1);
        ss.clear();
        for (int j = 0; j < n; j++) {
            ss.push_back(s0 + (s1 - s0) * j / (n - 1));
        }
        if (s_foot > s0 && s_foot < s1) {
            ss.push_back(s_foot);
            std::sort(ss.begin(), ss.end());
        }
        sm.clear();
        for (double s : ss) {
            const V3 P = pg.at(s);
            const V3 rel = P - r.o;
            const double rr = norm(rel);
            const V3 d = (1.0 / rr) * rel;
            const double h = std::hypot(rel.x, rel.y);
            const double e = sim_r2d(std::atan2(rel.z, h));
            const double bw = std::atan2(rel.y, rel.x);
            const double az = wrap180(r.heading_deg - sim_r2d(bw) - a_c);
            const double dv = dot(d, pg.v);
            const double re = pg.radius / std::sqrt(std::max(1e-12, 1.0 - dv * dv));
            const double tl = -std::sin(bw) * pg.lean.x + std::cos(bw) * pg.lean.y;
            const double rt = pg.radius * std::sqrt(1.0 + pg.tan_psi * pg.tan_psi * tl * tl);
            const double wdeg = sim_r2d(std::asin(std::min(1.0, rt / std::max(h, 1e-9))));
            double g = elevation_gain(e) * azimuth_gain(az);
            if (ke) {
                g *= ke_at(s);
            }
            const double rf = pg.reflectivity * seg(s);
            sm.push_back({rr, re, e, rf * g * 2.0 * wdeg, rf * g});
            if (!ke || (s >= geo[rq].first && s <= geo[rq].second)) {
                r1 = std::min(r1, rr - re);
                r2 = std::max(r2, rr);
            }
        }
        if (col == nullptr) {
            continue;
        }
        // the range-response path: the energy on sub-cells of bin / kSimFineQ
        std::vector<double> fe;
        long f0 = 0;
        if (fine) {
            double lo = std::numeric_limits<double>::infinity(), hi = 0;
            for (const Smp &A : sm) {
                lo = std::min(lo, A.r - A.re);
                hi = std::max(hi, A.r);
            }
            if (!(hi >= lo)) {
                continue;
            }
            f0 = std::max(0L, static_cast<long>(std::floor(lo / bin * kSimFineQ)) - 1);
            const long f1 = static_cast<long>(std::floor(hi / bin * kSimFineQ)) + 1;
            fe.assign(static_cast<size_t>(std::max(1L, f1 - f0 + 1)), 0.0);
        }
        for (size_t j = 0; j + 1 < sm.size(); j++) {
            const Smp &A = sm[j], &B = sm[j + 1];
            const double E = 0.5 * (A.eps + B.eps) * std::fabs(B.e - A.e);
            const double re = 0.5 * (A.re + B.re);
            if (fine) {
                sim_splat_profile(fe, bin / kSimFineQ, A.r, B.r, re, E, static_cast<int>(f0));
            } else {
                sim_splat_profile(col->energy, bin, A.r, B.r, re, E, 0);
            }
            if (A.g > 0 || B.g > 0) {
                touch(*col, bin, std::min(A.r, B.r) - re, std::max(A.r, B.r),
                      static_cast<float>(std::max(A.g, B.g)));
            }
        }
        for (size_t q = 0; q < fe.size(); q++) {
            if (fe[q] > 0) {
                col->fine.emplace_back(f0 + static_cast<long>(q), fe[q]);
            }
        }
    }
    if (r1s != nullptr) {
        *r1s = r1;
    }
    if (r2s != nullptr) {
        *r2s = r2;
    }
}

void Simulator::ground_analytic(int i, SimColumn &col) const
{
    const BoardSpec &b = s_.board;
    const double H = b.radar_height_m, bin = bin_m();
    const int K = s_.ground_az_samples;
    const int nb = bins();
    const int last = std::min(nb - 1, static_cast<int>(std::floor(s_.ground_max_range_m / bin)));
    auto C = [&](double x) {
        const double u = std::clamp(x, 0.0, 90.0) / ground_cum_step_;
        const size_t n = std::min(ground_cum_.size() - 2, static_cast<size_t>(u));
        const double f = u - static_cast<double>(n);
        return ground_cum_[n] + f * (ground_cum_[n + 1] - ground_cum_[n]);
    };
    for (int k = 0; k < K; k++) {
        const double d = K == 1 ? 0.0 : -cut_az_ + 2.0 * cut_az_ * k / (K - 1);
        const double wk = K == 1 ? 1.0 : (2.0 * cut_az_ / (K - 1)) * ((k == 0 || k == K - 1) ? 0.5 : 1.0);
        const double g = azimuth_gain(d) * wk;
        if (g <= 0) {
            continue;
        }
        const double th = chassis_theta_deg(b, az_deg_[static_cast<size_t>(i)] + d);
        const double lo_d = std::max(0.0, -s_.elev_top_deg);
        // knife edge: the ground inside the geometric shadow is lit by diffraction (every
        // depression of the wedge, weighted by the two-way loss)
        const double hi_d = s_.knife_edge && std::isfinite(th) ? -s_.elev_bottom_deg
                                                               : std::min(th, -s_.elev_bottom_deg);
        if (!(hi_d > lo_d)) {
            continue;
        }
        const double r_first = H / std::sin(sim_d2r(hi_d));
        for (int j = std::max(0, static_cast<int>(std::floor(r_first / bin))); j <= last; j++) {
            const double ra = j * bin, rb = (j + 1) * bin;
            if (rb <= H) {
                continue;
            }
            const double x_hi = ra <= H ? 90.0 : sim_r2d(std::asin(H / ra));
            const double x_lo = sim_r2d(std::asin(H / rb));
            const double a = std::max(x_lo, lo_d), c = std::min(x_hi, hi_d);
            if (c <= a) {
                continue;
            }
            double E = s_.ground_reflectivity * g * (C(c) - C(a));
            if (s_.knife_edge) {
                E *= knife_edge_gain(az_deg_[static_cast<size_t>(i)] + d, -0.5 * (a + c), (j + 0.5) * bin);
                if (E < 1e-6 * s_.ground_reflectivity * g * (C(c) - C(a))) {
                    continue;
                }
            }
            col.energy[static_cast<size_t>(j)] += E;
            if (E > 0) {
                col.touched[static_cast<size_t>(j)] = 1;
                col.peak[static_cast<size_t>(j)] = std::max(
                    col.peak[static_cast<size_t>(j)],
                    static_cast<float>(s_.ground_reflectivity * azimuth_gain(d) *
                                       elevation_gain(-0.5 * (a + c))));
            }
        }
    }
}

double scene_ground_z(const Scene &s, double x, double y)
{
    double z = 0;
    for (const auto &t : s.terrain) {
        const double a = sim_d2r(t.dir_deg);
        const double u = (x - t.x_m) * std::cos(a) + (y - t.y_m) * std::sin(a);
        if (u >= 0 && (!t.strip || u < t.width_m)) {
            z += t.height_m;
        }
    }
    return z;
}

bool scene_terrain(const Scene &s)
{
    return !s.terrain.empty() || s.pitch_deg != 0.0 || s.roll_deg != 0.0 ||
           s.height_offset_m != 0.0;
}

void Simulator::ground_terrain(const RadarPose &r, int i, SimColumn &col) const
{
    const BoardSpec &b = s_.board;
    const double H = b.radar_height_m + s_.height_offset_m, bin = bin_m();
    const int nb = bins();
    // a few bearings across the beam: the terrain path marches every one of them
    const int K = std::min(s_.ground_az_samples, 9);
    const double step = 0.01, rmax = s_.ground_max_range_m;
    auto C = [&](double x) {
        const double u = std::clamp(x, 0.0, 90.0) / ground_cum_step_;
        const size_t n = std::min(ground_cum_.size() - 2, static_cast<size_t>(u));
        const double f = u - static_cast<double>(n);
        return ground_cum_[n] + f * (ground_cum_[n + 1] - ground_cum_[n]);
    };
    const double cp = std::cos(sim_d2r(s_.pitch_deg)), sp = std::sin(sim_d2r(s_.pitch_deg));
    const double cq = std::cos(sim_d2r(s_.roll_deg)), sq = std::sin(sim_d2r(s_.roll_deg));
    const double h = sim_d2r(r.heading_deg);
    const double fx = std::cos(h), fy = std::sin(h);
    for (int k = 0; k < K; k++) {
        const double d = K == 1 ? 0.0 : -cut_az_ + 2.0 * cut_az_ * k / (K - 1);
        const double wk = K == 1 ? 1.0 : (2.0 * cut_az_ / (K - 1)) * ((k == 0 || k == K - 1) ? 0.5 : 1.0);
        const double g = azimuth_gain(d) * wk;
        if (g <= 0) {
            continue;
        }
        const double phi = az_deg_[static_cast<size_t>(i)] + d;
        const double th = chassis_theta_deg(b, phi);
        const double lo_d = std::max(0.0, -s_.elev_top_deg);
        const double hi_d = s_.knife_edge && std::isfinite(th) ? -s_.elev_bottom_deg
                                                               : std::min(th, -s_.elev_bottom_deg);
        if (!(hi_d > lo_d)) {
            continue;
        }
        // the bearing's direction on the ground (vehicle frame: clockwise from forward)
        const double vxh = std::cos(sim_d2r(phi)), vyh = -std::sin(sim_d2r(phi));
        const double ux = vxh * fx - vyh * fy, uy = vxh * fy + vyh * fx;
        double seen = 90.0, prev_r = H;
        for (double rho = step; rho <= rmax; rho += step) {
            const double px = r.o.x + rho * ux, py = r.o.y + rho * uy;
            const double wz = scene_ground_z(s_, px, py) - H;
            // level frame (heading removed) -> vehicle frame: Rx(roll)^T Ry(pitch)^T
            const double wx = rho * vxh, wy = rho * vyh;
            const double ax = cp * wx - sp * wz, az = sp * wx + cp * wz;
            const double vx = ax, vy = cq * wy + sq * az, vz = -sq * wy + cq * az;
            const double x = sim_r2d(std::atan2(-vz, std::hypot(vx, vy)));
            const double rr = std::sqrt(rho * rho + wz * wz);
            if (x < seen) {
                const double a = std::max(x, lo_d), c = std::min(seen, hi_d);
                const double rm = 0.5 * (rr + prev_r);
                const int j = static_cast<int>(std::floor(rm / bin));
                if (c > a && j >= 0 && j < nb) {
                    double E = s_.ground_reflectivity * g * (C(c) - C(a));
                    if (s_.knife_edge) {
                        E *= knife_edge_gain(phi, -0.5 * (a + c), rm);
                    }
                    col.energy[static_cast<size_t>(j)] += E;
                    if (E > 0) {
                        col.touched[static_cast<size_t>(j)] = 1;
                        col.peak[static_cast<size_t>(j)] = std::max(
                            col.peak[static_cast<size_t>(j)],
                            static_cast<float>(s_.ground_reflectivity * azimuth_gain(d) *
                                               elevation_gain(-0.5 * (a + c))));
                    }
                }
                seen = x;
            }
            prev_r = rr;
        }
    }
}

bool Simulator::boxes_in_window(const RadarPose &r, int i) const
{
    const double a_c = az_deg_[static_cast<size_t>(i)];
    for (const auto &bx : boxes_) {
        double lo = 1e9, hi = -1e9;
        for (int q = 0; q < 4; q++) {
            const double u = (q & 1) ? bx.hx : -bx.hx, v = (q & 2) ? bx.hy : -bx.hy;
            const V3 P{bx.cx + bx.c * u - bx.s * v, bx.cy + bx.s * u + bx.c * v, 0};
            const double d = wrap180(azimuth_of(r, P) - a_c);
            lo = std::min(lo, d);
            hi = std::max(hi, d);
        }
        if (hi - lo >= 180.0) {
            return true; // the radar is inside or beside it: take the slow path
        }
        if (hi >= -cut_az_ && lo <= cut_az_) {
            return true;
        }
    }
    return false;
}

void Simulator::grid_ground_boxes(const RadarPose &r, int i, SimColumn &col) const
{
    const BoardSpec &b = s_.board;
    const double H = b.radar_height_m, bin = bin_m();
    const int K = s_.ground_az_samples;
    const double a_c = az_deg_[static_cast<size_t>(i)];
    const int ne = std::max(2, static_cast<int>(std::ceil((s_.elev_top_deg - s_.elev_bottom_deg) /
                                                          s_.box_step_deg)) + 1);
    struct Hit {
        int surf; // -2 none, -1 ground, >= 0 box
        double t, eps, g;
    };
    std::vector<Hit> hits(static_cast<size_t>(ne));
    for (int k = 0; k < K; k++) {
        const double d = K == 1 ? 0.0 : -cut_az_ + 2.0 * cut_az_ * k / (K - 1);
        const double wk = K == 1 ? 1.0 : (2.0 * cut_az_ / (K - 1)) * ((k == 0 || k == K - 1) ? 0.5 : 1.0);
        const double ga = azimuth_gain(d);
        if (ga <= 0) {
            continue;
        }
        const double th = chassis_theta_deg(b, a_c + d);
        const double bw = sim_d2r(r.heading_deg - (a_c + d));
        for (int j = 0; j < ne; j++) {
            const double e = s_.elev_bottom_deg + (s_.elev_top_deg - s_.elev_bottom_deg) * j / (ne - 1);
            Hit h{-2, 0, 0, 0};
            if (e >= -th) {
                const double ce = std::cos(sim_d2r(e)), se = std::sin(sim_d2r(e));
                const V3 dir{ce * std::cos(bw), ce * std::sin(bw), se};
                double tg = std::numeric_limits<double>::infinity();
                if (se < 0) {
                    tg = H / -se;
                    if (tg * ce > s_.ground_max_range_m) {
                        tg = std::numeric_limits<double>::infinity();
                    }
                }
                double tb = std::min(tg, 1e6);
                int which = -2;
                for (size_t q = 0; q < boxes_.size(); q++) {
                    double t = 0;
                    if (boxes_[q].hit(r.o, dir, 1e-6, tb, &t)) {
                        tb = t;
                        which = static_cast<int>(q);
                    }
                }
                const double gel = elevation_gain(e);
                if (which >= 0) {
                    const double g = boxes_[static_cast<size_t>(which)].reflectivity * gel * ga;
                    h = Hit{which, tb, g * wk, g};
                } else if (std::isfinite(tg) && s_.ground) {
                    const double sh = s_.ground_ambient + (1 - s_.ground_ambient) * -se;
                    const double g = s_.ground_reflectivity * sh * gel * ga;
                    h = Hit{-1, tg, g * wk, g};
                }
            }
            hits[static_cast<size_t>(j)] = h;
        }
        const double de = (s_.elev_top_deg - s_.elev_bottom_deg) / (ne - 1);
        for (int j = 0; j + 1 < ne; j++) {
            const Hit &A = hits[static_cast<size_t>(j)], &B = hits[static_cast<size_t>(j) + 1];
            if (A.surf == -2 || A.surf != B.surf) {
                continue;
            }
            add_uniform(col.energy, bin, A.t, B.t, 0.5 * (A.eps + B.eps) * de);
            if (A.g > 0 || B.g > 0) {
                touch(col, bin, A.t, B.t, static_cast<float>(std::max(A.g, B.g)));
            }
        }
    }
}

void Simulator::column_from(const RotationGeom &rg, int i, SimColumn &col) const
{
    col.reset(bins());
    const RadarPose pose = radar_pose_at(s_, time_of(rg.k, i));
    if (!boxes_.empty() && boxes_in_window(pose, i)) {
        grid_ground_boxes(pose, i, col);
    } else if (s_.ground && terrain_moving_) {
        ground_terrain(pose, i, col);
    } else if (s_.ground && !ground_cols_.empty()) {
        const auto &g = ground_cols_[ground_cols_.size() == 1 ? 0 : static_cast<size_t>(i)];
        for (size_t j = 0; j < g.size(); j++) {
            if (g[j] > 0) {
                col.energy[j] += g[j];
                col.touched[j] = 1;
                col.peak[j] = std::max(col.peak[j], static_cast<float>(s_.ground_reflectivity));
            }
        }
    }
    for (const auto &pv : rg.per_az[static_cast<size_t>(i)]) {
        splat_pole(pv, i, &col, nullptr, nullptr);
    }
    if (!s_.points.empty()) {
        add_points(rg.k, i, pose, col);
    }
}

void Simulator::geometry_column(int k, int i, SimColumn &col) const
{
    RotationGeom rg;
    rotation_geom(k, rg);
    column_from(rg, i, col);
}

// ------------------------------------------------------------------------------------------
// effects and the 8-bit mapping

void Simulator::map_column(int k, int i, const SimColumn &col, uint8_t *out) const
{
    const int nb = bins();
    const double bin = bin_m();
    const bool frozen = scene_speckle_static(s_);
    const uint64_t spk_seed = s_.speckle_seed != 0 ? s_.speckle_seed : sim_hash(s_.seed, kSaltSpeckle);
    const uint64_t spk_k = frozen ? 0 : static_cast<uint64_t>(k) + 1;
    std::vector<double> E(col.energy);
    if (s_.amplitude == AmplitudeModel::Peak) {
        for (int j = 0; j < nb; j++) {
            E[static_cast<size_t>(j)] = col.peak[static_cast<size_t>(j)];
        }
    }
    // speckle belongs to the scatterers (interference inside a resolution cell); the smear
    // is the sensor's deterministic range response applied to what they return
    if (s_.speckle && !s_.speckle_physical) {
        for (int j = 0; j < nb; j++) {
            if (E[static_cast<size_t>(j)] > 0) {
                const double g = sim_normal(sim_hash(spk_seed, spk_k, static_cast<uint64_t>(i),
                                                     static_cast<uint64_t>(j)));
                double x = 0.1 * s_.speckle_db * g; // (this exact expression: same bytes as before)
                if (s_.speckle_frame_db > 0) {
                    x += 0.1 * s_.speckle_frame_db *
                         sim_normal(sim_hash(spk_seed ^ kSaltFrame, static_cast<uint64_t>(k) + 1,
                                             static_cast<uint64_t>(i), static_cast<uint64_t>(j)));
                }
                E[static_cast<size_t>(j)] *= std::pow(10.0, x);
            }
        }
    }
    if (scene_physical_response(s_)) {
        response_power(k, i, col, E);
    } else {
        for (const SimPoint &p : col.points) {
            const long j = static_cast<long>(std::floor(p.x_bins));
            if (j >= 0 && j < nb) {
                E[static_cast<size_t>(j)] += p.e;
            }
        }
    }
    if (s_.smear && s_.smear_shape == 2) {
        // two-component smear: the kernel of each source bin depends on its level
        std::vector<double> S(static_cast<size_t>(nb), 0.0);
        const int W = std::max(1, static_cast<int>(std::lround(s_.smear_width_bins)));
        const double slow0 = std::pow(10.0, 0.1 * s_.smear_slow_db);
        const double front = s_.smear_front_db <= -100 ? 0.0 : std::pow(10.0, 0.1 * s_.smear_front_db);
        for (int j = 0; j < nb; j++) {
            const double v = E[static_cast<size_t>(j)];
            if (v <= 0) {
                continue;
            }
            const double x = std::clamp(0.5 * std::log10(v / s_.log_ref_energy), -1.0, 1.0);
            const double df = std::max(0.05, s_.smear_decay_db - s_.smear_amp_decay_db * x);
            const double ds = std::max(0.05, s_.smear_slow_decay_db - s_.smear_amp_decay_db * x);
            const double af = std::pow(10.0, -0.1 * df), as = std::pow(10.0, -0.1 * ds);
            if (j > 0) {
                S[static_cast<size_t>(j) - 1] += v * front;
            }
            double kf = 1.0, ks = slow0;
            for (int q = 0; q < W && j + q < nb; q++) {
                S[static_cast<size_t>(j + q)] += v * (kf + ks);
                kf *= af;
                ks *= as;
            }
        }
        E.swap(S);
    } else if (s_.smear) {
        std::vector<double> S(static_cast<size_t>(nb), 0.0);
        const int nk = static_cast<int>(smear_kernel_.size());
        for (int j = 0; j < nb; j++) {
            const double v = E[static_cast<size_t>(j)];
            if (v <= 0) {
                continue;
            }
            for (int q = 0; q < nk; q++) {
                const int t = j - smear_front_ + q;
                if (t >= 0 && t < nb) {
                    S[static_cast<size_t>(t)] += v * smear_kernel_[static_cast<size_t>(q)];
                }
            }
        }
        E.swap(S);
    }
    if (s_.mapping == OutputMapping::Linear) {
        double scale = s_.linear_scale;
        if (s_.normalize == Normalize::Column) {
            const double mx = *std::max_element(E.begin(), E.end());
            scale = mx > 0 ? s_.peak_counts / mx : 0.0;
        }
        for (int j = 0; j < nb; j++) {
            long v = std::lround(E[static_cast<size_t>(j)] * scale);
            if (!s_.smear && col.touched[static_cast<size_t>(j)] != 0 && v < s_.detect_floor) {
                v = s_.detect_floor;
            }
            out[j] = static_cast<uint8_t>(std::clamp(v, 0L, 255L));
        }
        return;
    }
    // log-magnitude mapping with leakage and noise
    const double c = s_.log_db_per_decade;
    // N = round(|a|) (magnitude) or round(|a|^2) (power): |a| at the reference energy
    const double n_ref = s_.log_power ? std::pow(10.0, s_.log_ref_value / (2 * c))
                                      : std::pow(10.0, s_.log_ref_value / c);
    for (int j = 0; j < nb; j++) {
        const double r = (j + 0.5) * bin;
        double aL = 0;
        if (s_.leakage) {
            double L = 0;
            if (r <= s_.leak_edge_m) {
                L = s_.leak_level;
            } else if (r <= s_.leak_edge_m + 0.2) {
                L = s_.leak_level + (s_.leak_shoulder - s_.leak_level) * (r - s_.leak_edge_m) / 0.2;
            } else if (r <= s_.leak_shoulder_end_m) {
                L = s_.leak_shoulder;
            } else if (r <= s_.leak_shoulder_end_m + 0.3) {
                L = s_.leak_shoulder * (1.0 - (r - s_.leak_shoulder_end_m) / 0.3);
            }
            if (L > 0) {
                const double jit = sim_normal(sim_hash(s_.seed, kSaltLeak, static_cast<uint64_t>(i),
                                                       static_cast<uint64_t>(j)));
                aL = std::max(0.0, std::pow(10.0, L / (s_.log_power ? 2 * c : c)) *
                                       (1.0 + s_.leak_jitter * jit));
            }
        }
        const double Ej = E[static_cast<size_t>(j)];
        const double aS = Ej > 0 ? n_ref * std::sqrt(Ej / s_.log_ref_energy) : 0.0;
        const uint64_t hn = sim_hash(s_.seed, kSaltNoise ^ (static_cast<uint64_t>(k) << 20),
                                     static_cast<uint64_t>(i), static_cast<uint64_t>(j));
        if (aS == 0 && aL == 0) {
            if (!s_.noise) {
                out[j] = 0;
                continue;
            }
            const double u = sim_uniform(hn);
            const size_t m = static_cast<size_t>(
                std::upper_bound(noise_cdf_.begin(), noise_cdf_.end(), u) - noise_cdf_.begin());
            out[j] = noise_val_[std::min(m, noise_val_.size() - 1)];
            continue;
        }
        double re = 0, im = 0;
        if (aS > 0) {
            const double ph = s_.speckle ? 2 * kSimPi * sim_uniform(sim_hash(spk_seed ^ kSaltPhase, spk_k,
                                                                              static_cast<uint64_t>(i),
                                                                              static_cast<uint64_t>(j)))
                                         : 0.0;
            re += aS * std::cos(ph);
            im += aS * std::sin(ph);
        }
        if (aL > 0) {
            const double ph = 2 * kSimPi * sim_uniform(sim_hash(s_.seed, kSaltLeak ^ kSaltPhase,
                                                                static_cast<uint64_t>(i),
                                                                static_cast<uint64_t>(j)));
            re += aL * std::cos(ph);
            im += aL * std::sin(ph);
        }
        if (s_.noise) {
            re += s_.noise_sigma * sim_normal(hn);
            im += s_.noise_sigma * sim_normal(sim_hash(hn, 1));
        }
        const long nq = std::lround(s_.log_power ? re * re + im * im : std::hypot(re, im));
        const double v = log_value(nq);
        out[j] = static_cast<uint8_t>(std::min(255.0, v));
    }
}

// The range-response path. Sources: every bin's energy (ground, boxes; at the bin's centre),
// the poles' sub-cells and the point returns. Physical speckle: each bin and sub-cell is a
// resolution cell of many sub-scatterers, a circular complex Gaussian amplitude of mean power
// its energy (drawn per rotation, or once when frozen); a point return is one scatterer of
// amplitude sqrt(E) and carrier phase 4 pi r / lambda. The field per bin is the sum of the
// amplitudes times sqrt(R) at their offset, the power |field|^2. Without physical speckle the
// expected power sum E R(offset) (log-normal speckle, if on, already scaled the energies).
void Simulator::response_power(int k, int i, const SimColumn &col, std::vector<double> &E) const
{
    const int nb = bins();
    const bool phys = s_.speckle && s_.speckle_physical;
    const bool frozen = scene_speckle_static(s_);
    const uint64_t spk_seed = s_.speckle_seed != 0 ? s_.speckle_seed : sim_hash(s_.seed, kSaltSpeckle);
    const uint64_t spk_k = frozen ? 0 : static_cast<uint64_t>(k) + 1;
    const int H = resp_half_;
    std::vector<double> fr(static_cast<size_t>(nb), 0.0), fi(static_cast<size_t>(nb), 0.0);
    std::vector<double> P(static_cast<size_t>(nb), 0.0);
    // a source at x bins (bin j spans [j, j + 1), so offset o = m + 1/2 - x) of energy e and
    // complex amplitude (ar, ai)
    auto add = [&](double x, double e, double ar, double ai) {
        if (resp_delta_) {
            const long m = static_cast<long>(std::floor(x));
            if (m >= 0 && m < nb) {
                fr[static_cast<size_t>(m)] += ar;
                fi[static_cast<size_t>(m)] += ai;
                P[static_cast<size_t>(m)] += e;
            }
            return;
        }
        const long m0 = std::max(0L, static_cast<long>(std::ceil(x - 0.5 - H)));
        const long m1 = std::min(static_cast<long>(nb) - 1, static_cast<long>(std::floor(x - 0.5 + H)));
        for (long m = m0; m <= m1; m++) {
            const double u = (static_cast<double>(m) + 0.5 - x + H) * kRespSub;
            const size_t t = std::min(resp_pow_.size() - 2, static_cast<size_t>(std::max(0.0, u)));
            const double f = std::clamp(u - static_cast<double>(t), 0.0, 1.0);
            if (phys) {
                const double a = resp_amp_[t] + f * (resp_amp_[t + 1] - resp_amp_[t]);
                fr[static_cast<size_t>(m)] += a * ar;
                fi[static_cast<size_t>(m)] += a * ai;
            } else {
                P[static_cast<size_t>(m)] += e * (resp_pow_[t] + f * (resp_pow_[t + 1] - resp_pow_[t]));
            }
        }
    };
    auto gauss = [&](uint64_t salt, uint64_t cell, double e, double *ar, double *ai) {
        const uint64_t h = sim_hash(spk_seed ^ salt, spk_k, static_cast<uint64_t>(i), cell);
        const double sd = std::sqrt(0.5 * e);
        *ar = sd * sim_normal(h);
        *ai = sd * sim_normal(sim_hash(h, 1));
    };
    for (int j = 0; j < nb; j++) {
        const double e = E[static_cast<size_t>(j)];
        if (e > 0) {
            double ar = std::sqrt(e), ai = 0;
            if (phys) {
                gauss(kSaltPhysBin, static_cast<uint64_t>(j), e, &ar, &ai);
            }
            add(j + 0.5, e, ar, ai);
        }
    }
    if (!col.fine.empty()) {
        std::vector<std::pair<long, double>> fine(col.fine);
        std::sort(fine.begin(), fine.end());
        for (size_t q = 0; q < fine.size();) {
            const long cell = fine[q].first;
            double e = 0;
            for (; q < fine.size() && fine[q].first == cell; q++) {
                e += fine[q].second;
            }
            if (s_.speckle && !s_.speckle_physical) {
                // log-normal speckle: the draw of the bin the sub-cell lies in
                const long j = cell / kSimFineQ;
                double x = 0.1 * s_.speckle_db *
                           sim_normal(sim_hash(spk_seed, spk_k, static_cast<uint64_t>(i), static_cast<uint64_t>(j)));
                if (s_.speckle_frame_db > 0) {
                    x += 0.1 * s_.speckle_frame_db *
                         sim_normal(sim_hash(spk_seed ^ kSaltFrame, static_cast<uint64_t>(k) + 1,
                                             static_cast<uint64_t>(i), static_cast<uint64_t>(j)));
                }
                e *= std::pow(10.0, x);
            }
            double ar = std::sqrt(e), ai = 0;
            if (phys) {
                gauss(kSaltPhysFine, static_cast<uint64_t>(cell), e, &ar, &ai);
            }
            add((static_cast<double>(cell) + 0.5) / kSimFineQ, e, ar, ai);
        }
    }
    const double lambda = 0.299792458 / s_.carrier_ghz;
    for (const SimPoint &p : col.points) {
        const double ph = 4.0 * kSimPi * p.r_m / lambda;
        const double a = std::sqrt(p.e);
        add(p.x_bins, p.e, a * std::cos(ph), a * std::sin(ph));
    }
    for (int m = 0; m < nb; m++) {
        const size_t u = static_cast<size_t>(m);
        E[u] = phys ? fr[u] * fr[u] + fi[u] * fi[u] : P[u];
    }
}

// Clutter: weak returns in a band just inside the shadow edge (slant S(az) - inner_m ..
// S(az) - outer_m), fixed to the vehicle. Each cell returns with probability `density` and a
// value uniform in [value_min, value_max]; both are redrawn every `change_rotations`
// rotations, staggered per cell (0: drawn once). Counter-based: same seed, same bytes.
void Simulator::apply_clutter(int k, int i, uint8_t *out) const
{
    if (!s_.clutter) {
        return;
    }
    const BoardSpec &b = s_.board;
    const double rs = b.shadow_radius_m(i), h = b.radar_height_m;
    const double edge = std::sqrt(rs * rs + h * h);
    const double lo = edge - s_.clutter_inner_m, hi = edge - s_.clutter_outer_m;
    const double bin = bin_m();
    const int nb = bins();
    const int j0 = std::max(0, static_cast<int>(std::ceil(lo / bin - 0.5)));
    const int j1 = std::min(nb - 1, static_cast<int>(std::floor(hi / bin - 0.5)));
    const uint64_t span = static_cast<uint64_t>(s_.clutter_value_max - s_.clutter_value_min) + 1U;
    const uint64_t salt = sim_hash(s_.seed, kSaltClutter);
    for (int j = j0; j <= j1; j++) {
        uint64_t epoch = 0;
        if (s_.clutter_change_rotations > 0) {
            const uint64_t per = static_cast<uint64_t>(s_.clutter_change_rotations);
            const uint64_t phase = sim_hash(salt, static_cast<uint64_t>(i), static_cast<uint64_t>(j)) % per;
            epoch = (static_cast<uint64_t>(k) + phase) / per + 1U;
        }
        const uint64_t hc = sim_hash(salt ^ 0x5A5AULL, epoch, static_cast<uint64_t>(i),
                                     static_cast<uint64_t>(j));
        if (sim_uniform(hc) >= s_.clutter_density) {
            continue;
        }
        const uint64_t v = static_cast<uint64_t>(s_.clutter_value_min) + sim_hash(hc, 7) % span;
        if (v > out[j]) {
            out[j] = static_cast<uint8_t>(v);
        }
    }
}

std::vector<uint8_t> Simulator::render_bins(int k, int i) const
{
    std::vector<uint8_t> out(static_cast<size_t>(bins()));
    if (!static_cols_.empty()) {
        map_column(k, i, static_cols_[static_cast<size_t>(i)], out.data());
        apply_clutter(k, i, out.data());
        return out;
    }
    SimColumn col;
    geometry_column(k, i, col);
    map_column(k, i, col, out.data());
    apply_clutter(k, i, out.data());
    return out;
}

void Simulator::render_rotation(int k, std::vector<uint8_t> &bytes, std::vector<GtRow> &gt) const
{
    RotationGeom rg;
    rotation_geom(k, rg);
    gt.insert(gt.end(), rg.gt.begin(), rg.gt.end());
    const int N = azimuths(), nb = bins();
    const size_t msg = SL_PROTO_HEADER_BYTES + SL_PROTO_FFT_FIXED_BYTES + static_cast<size_t>(nb);
    size_t at = bytes.size();
    bytes.resize(at + msg * static_cast<size_t>(N));
    SimColumn col;
    for (int i = 0; i < N; i++) {
        sl_proto_fft_t f;
        std::memset(&f, 0, sizeof f);
        f.id = SL_PROTO_ID_FFT_DATA;
        f.bytes_per_bin = 1;
        f.data_offset = SL_PROTO_FFT_FIXED_BYTES;
        f.sweep_counter = static_cast<uint16_t>((static_cast<long long>(k) * N + i) & 0xFFFF);
        f.azimuth_ticks = ticks_of(i);
        sim_split_time(s_.start_time_s + time_of(k, i), &f.seconds, &f.split_ns);
        f.bins = static_cast<uint32_t>(nb);
        const sl_ssize_t n = sl_proto_encode_fft_head(bytes.data() + at, msg, &f);
        if (n != static_cast<sl_ssize_t>(SL_PROTO_HEADER_BYTES + SL_PROTO_FFT_FIXED_BYTES)) {
            throw SceneError("sl_proto_encode_fft_head failed");
        }
        uint8_t *out = bytes.data() + at + static_cast<size_t>(n);
        const bool plain = !static_cols_.empty() ||
                           (rg.per_az[static_cast<size_t>(i)].empty() &&
                            (boxes_.empty() ||
                             !boxes_in_window(radar_pose_at(s_, time_of(k, i)), i)));
        if (deterministic_ && plain) {
            std::memcpy(out, out_cache_[static_cast<size_t>(i)].data(), static_cast<size_t>(nb));
        } else if (!static_cols_.empty()) {
            map_column(k, i, static_cols_[static_cast<size_t>(i)], out);
        } else {
            column_from(rg, i, col);
            map_column(k, i, col, out);
        }
        apply_clutter(k, i, out);
        at += msg;
    }
}

void sim_run(const Simulator &sim, int first, int count, int threads,
             const std::function<void(int k, std::vector<uint8_t> &bytes, std::vector<GtRow> &gt)> &sink,
             const std::function<void(int done, int total)> &progress)
{
    if (threads <= 0) {
        threads = static_cast<int>(std::max(1U, std::thread::hardware_concurrency()));
    }
    threads = std::max(1, std::min(threads, count));
    if (threads == 1) {
        for (int n = 0; n < count; n++) {
            std::vector<uint8_t> bytes;
            std::vector<GtRow> gt;
            sim.render_rotation(first + n, bytes, gt);
            sink(first + n, bytes, gt);
            if (progress) {
                progress(n + 1, count);
            }
        }
        return;
    }
    // A ring of 2 * threads slots; worker w renders rotations n with n % threads == w
    // (static assignment keeps the ring ordered); the caller consumes in order.
    const int slots = 2 * threads;
    struct Slot {
        int n = -1;
        bool ready = false;
        std::vector<uint8_t> bytes;
        std::vector<GtRow> gt;
    };
    std::vector<Slot> ring(static_cast<size_t>(slots));
    std::mutex mu;
    std::condition_variable cv;
    std::atomic<bool> failed{false};
    std::string error;
    int consumed = 0;
    auto worker = [&](int w) {
        for (int n = w; n < count && !failed; n += threads) {
            Slot &sl = ring[static_cast<size_t>(n % slots)];
            {
                std::unique_lock<std::mutex> lk(mu);
                cv.wait(lk, [&] { return failed || n < consumed + slots; });
                if (failed) {
                    return;
                }
            }
            std::vector<uint8_t> bytes;
            std::vector<GtRow> gt;
            try {
                sim.render_rotation(first + n, bytes, gt);
            } catch (const std::exception &e) {
                std::lock_guard<std::mutex> lk(mu);
                failed = true;
                error = e.what();
                cv.notify_all();
                return;
            }
            std::lock_guard<std::mutex> lk(mu);
            sl.n = n;
            sl.bytes.swap(bytes);
            sl.gt.swap(gt);
            sl.ready = true;
            cv.notify_all();
        }
    };
    std::vector<std::thread> pool;
    for (int w = 0; w < threads; w++) {
        pool.emplace_back(worker, w);
    }
    for (int n = 0; n < count; n++) {
        Slot &sl = ring[static_cast<size_t>(n % slots)];
        std::vector<uint8_t> bytes;
        std::vector<GtRow> gt;
        {
            std::unique_lock<std::mutex> lk(mu);
            cv.wait(lk, [&] { return failed || (sl.ready && sl.n == n); });
            if (failed) {
                break;
            }
            bytes.swap(sl.bytes);
            gt.swap(sl.gt);
            sl.ready = false;
        }
        try {
            sink(first + n, bytes, gt);
        } catch (...) {
            {
                std::lock_guard<std::mutex> lk(mu);
                failed = true;
                cv.notify_all();
            }
            for (auto &t : pool) {
                t.join();
            }
            throw;
        }
        {
            std::lock_guard<std::mutex> lk(mu);
            consumed = n + 1;
            cv.notify_all();
        }
        if (progress) {
            progress(n + 1, count);
        }
    }
    for (auto &t : pool) {
        t.join();
    }
    if (failed) {
        throw SceneError("simulation failed: " + error);
    }
}

} // namespace sl
