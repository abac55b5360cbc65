// SPDX-License-Identifier: MIT
// sim_geom.cpp: see sim_geom.h.
#include "sim_geom.h"

#include <algorithm>
#include <limits>

namespace sl {

double wrap180(double deg)
{
    double a = std::fmod(deg + 180.0, 360.0);
    if (a < 0) {
        a += 360.0;
    }
    return a - 180.0;
}

double chassis_theta_deg(const BoardSpec &b, double az_vehicle_deg)
{
    return chassis_theta_deg(b, az_vehicle_deg, nullptr);
}

double chassis_theta_deg(const BoardSpec &b, double az_vehicle_deg, double *edge_m)
{
    const double H = b.radar_height_m;
    if (b.chassis_type == "cylinder") {
        if (edge_m != nullptr) {
            *edge_m = b.cylinder_radius_m;
        }
        return sim_r2d(std::atan2(H - b.cylinder_top_m, b.cylinder_radius_m));
    }
    // Same construction as BoardSpec::edge_along: ray (cos a, -sin a) in x-forward y-left;
    // the grazing edge is the crossing of least depression.
    const double a = sim_d2r(az_vehicle_deg);
    const double dx = std::cos(a), dy = -std::sin(a);
    double best = std::numeric_limits<double>::infinity(), best_t = 0;
    const size_t n = b.polygon.size();
    for (size_t k = 0; k < n; k++) {
        const ChassisVertex &p = b.polygon[k];
        const ChassisVertex &q = b.polygon[(k + 1) % n];
        const double ex = q.x_m - p.x_m, ey = q.y_m - p.y_m;
        const double det = dx * (-ey) - dy * (-ex);
        if (std::fabs(det) < 1e-12) {
            continue;
        }
        const double wx = p.x_m - b.radar_x_m, wy = p.y_m - b.radar_y_m;
        const double t = (wx * (-ey) - wy * (-ex)) / det;
        const double u = (dx * wy - dy * wx) / det;
        if (t <= 1e-9 || u < -1e-12 || u > 1.0 + 1e-12) {
            continue;
        }
        const double h = p.edge_height_m + u * (q.edge_height_m - p.edge_height_m);
        const double ang = std::atan2(H - h, t);
        if (ang < best) {
            best = ang;
            best_t = t;
        }
    }
    if (edge_m != nullptr) {
        *edge_m = best_t;
    }
    return std::isfinite(best) ? sim_r2d(best) : std::numeric_limits<double>::quiet_NaN();
}

PoleGeom make_pole_geom(const ScenePole &p)
{
    PoleGeom g;
    const double psi = sim_d2r(p.tilt_deg), phi = sim_d2r(p.lean_deg);
    g.lean = {std::cos(phi), std::sin(phi), 0};
    g.v = {std::sin(psi) * g.lean.x, std::sin(psi) * g.lean.y, std::cos(psi)};
    g.tan_psi = std::tan(psi);
    g.length = p.length_m;
    g.radius = p.radius_m;
    g.reflectivity = p.reflectivity;
    // (x, y) is the axis point at height at_height_m: walk back down to z = 0.
    const double s_at = p.at_height_m / g.v.z;
    g.base = V3{p.x_m, p.y_m, p.at_height_m} - s_at * g.v;
    g.base.z = 0;
    return g;
}

BoxGeom make_box_geom(const SceneBox &b)
{
    BoxGeom g;
    g.cx = b.cx_m;
    g.cy = b.cy_m;
    g.c = std::cos(sim_d2r(b.yaw_deg));
    g.s = std::sin(sim_d2r(b.yaw_deg));
    g.hx = 0.5 * b.size_x_m;
    g.hy = 0.5 * b.size_y_m;
    g.z0 = b.z0_m;
    g.z1 = b.z0_m + b.height_m;
    g.reflectivity = b.reflectivity;
    return g;
}

bool BoxGeom::hit(V3 o, V3 d, double tmin, double tmax, double *t) const
{
    // Into the box frame, then slabs.
    const double ox = o.x - cx, oy = o.y - cy;
    const double lo[3] = {-hx, -hy, z0}, hi[3] = {hx, hy, z1};
    const double oo[3] = {c * ox + s * oy, -s * ox + c * oy, o.z};
    const double dd[3] = {c * d.x + s * d.y, -s * d.x + c * d.y, d.z};
    double t0 = tmin, t1 = tmax;
    for (int k = 0; k < 3; k++) {
        if (std::fabs(dd[k]) < 1e-15) {
            if (oo[k] < lo[k] || oo[k] > hi[k]) {
                return false;
            }
            continue;
        }
        double a = (lo[k] - oo[k]) / dd[k], b = (hi[k] - oo[k]) / dd[k];
        if (a > b) {
            std::swap(a, b);
        }
        t0 = std::max(t0, a);
        t1 = std::min(t1, b);
        if (t0 > t1) {
            return false;
        }
    }
    *t = t0;
    return true;
}

RadarPose radar_pose_at(const Scene &s, double t_s)
{
    RadarPose r;
    r.t_s = t_s;
    // A circle of radius v / w at yaw rate w (heading h0 + w t), a straight line at w = 0.
    const double w = sim_d2r(s.yaw_rate_dps), h0 = sim_d2r(s.heading_deg);
    r.heading_deg = s.heading_deg + s.yaw_rate_dps * t_s;
    const double h = h0 + w * t_s;
    const double fx = std::cos(h), fy = std::sin(h);
    double vx = s.vehicle_x_m + s.speed_mps * t_s * fx;
    double vy = s.vehicle_y_m + s.speed_mps * t_s * fy;
    if (w != 0.0) {
        vx = s.vehicle_x_m + s.speed_mps / w * (std::sin(h) - std::sin(h0));
        vy = s.vehicle_y_m - s.speed_mps / w * (std::cos(h) - std::cos(h0));
    }
    // radar offset in the vehicle frame (x forward, y left)
    r.o.x = vx + s.board.radar_x_m * fx - s.board.radar_y_m * fy;
    r.o.y = vy + s.board.radar_x_m * fy + s.board.radar_y_m * fx;
    r.o.z = s.board.radar_height_m;
    return r;
}

double azimuth_of(const RadarPose &r, V3 p)
{
    const double b = sim_r2d(std::atan2(p.y - r.o.y, p.x - r.o.x));
    double a = std::fmod(r.heading_deg - b, 360.0);
    if (a < 0) {
        a += 360.0;
    }
    return a;
}

const char *seg_end_name(SegEnd e)
{
    switch (e) {
    case SegEnd::None: return "none";
    case SegEnd::Top: return "top";
    case SegEnd::Bottom: return "bottom";
    case SegEnd::Chassis: return "wedge";
    case SegEnd::Beam: return "beam";
    case SegEnd::Occluded: return "occluded";
    case SegEnd::Base: return "ground";
    case SegEnd::Tip: return "tip";
    }
    return "?";
}

namespace {

// Distance between segments [p0, p1] and [q0, q1] (Eberly's clamped closest points).
double seg_seg_dist(V3 p0, V3 p1, V3 q0, V3 q1)
{
    const V3 d1 = p1 - p0, d2 = q1 - q0, r = p0 - q0;
    const double a = dot(d1, d1), e = dot(d2, d2), f = dot(d2, r);
    double s = 0, t = 0;
    const double c = dot(d1, r), b = dot(d1, d2), den = a * e - b * b;
    if (den > 1e-18) {
        s = std::clamp((b * f - c * e) / den, 0.0, 1.0);
    }
    t = (b * s + f) / e;
    if (t < 0) {
        t = 0;
        s = std::clamp(-c / a, 0.0, 1.0);
    } else if (t > 1) {
        t = 1;
        s = std::clamp((b - c) / a, 0.0, 1.0);
    }
    return norm((p0 + s * d1) - (q0 + t * d2));
}

// Why point P of the axis is not visible (None = visible).
SegEnd hidden_by(const BoardSpec &b, const RadarPose &r, V3 P, int self, const Occluders &occ,
                 const Wedge &w, double az_center, double cutoff)
{
    const V3 rel = P - r.o;
    const double h = std::hypot(rel.x, rel.y);
    const double e = sim_r2d(std::atan2(rel.z, h));
    if (e > w.top_deg) {
        return SegEnd::Top;
    }
    if (e < w.bottom_deg) {
        return SegEnd::Bottom;
    }
    const double az = azimuth_of(r, P);
    const double th = chassis_theta_deg(b, az);
    if (!(e >= -th)) {
        return SegEnd::Chassis;
    }
    if (cutoff > 0 && std::fabs(wrap180(az - az_center)) > cutoff) {
        return SegEnd::Beam;
    }
    if (occ.boxes != nullptr) {
        for (const auto &bx : *occ.boxes) {
            double t = 0;
            if (bx.hit(r.o, rel, 1e-9, 1.0 - 1e-9, &t)) {
                return SegEnd::Occluded;
            }
        }
    }
    if (occ.poles != nullptr) {
        for (size_t k = 0; k < occ.poles->size(); k++) {
            if (static_cast<int>(k) == self) {
                continue;
            }
            const PoleGeom &q = (*occ.poles)[k];
            // shorten the sight line slightly so a pole touching P does not count
            const V3 P2 = r.o + 0.999 * rel;
            if (seg_seg_dist(r.o, P2, q.base, q.at(q.length)) < q.radius) {
                return SegEnd::Occluded;
            }
        }
    }
    return SegEnd::None;
}

} // namespace

VisibleAxis visible_axis(const BoardSpec &b, const RadarPose &r, const PoleGeom &p, int self,
                         const Occluders &occ, const Wedge &w, double az_center_deg,
                         double cutoff_deg, int samples)
{
    VisibleAxis va;
    const int n = std::max(8, samples);
    std::vector<SegEnd> why(static_cast<size_t>(n) + 1);
    auto at_s = [&](double s) { return hidden_by(b, r, p.at(s), self, occ, w, az_center_deg, cutoff_deg); };
    for (int k = 0; k <= n; k++) {
        why[static_cast<size_t>(k)] = at_s(p.length * k / n);
    }
    // Refine a transition between s_in (visible) and s_out (hidden): returns the boundary
    // and the reason just outside it.
    auto refine = [&](double s_in, double s_out, SegEnd *reason) {
        SegEnd rs = at_s(s_out);
        for (int it = 0; it < 80 && std::fabs(s_out - s_in) > 1e-10; it++) {
            const double m = 0.5 * (s_in + s_out);
            const SegEnd e = at_s(m);
            if (e == SegEnd::None) {
                s_in = m;
            } else {
                s_out = m;
                rs = e;
            }
        }
        *reason = rs;
        return s_in;
    };
    for (int k = 0; k <= n;) {
        if (why[static_cast<size_t>(k)] != SegEnd::None) {
            k++;
            continue;
        }
        int j = k;
        while (j + 1 <= n && why[static_cast<size_t>(j) + 1] == SegEnd::None) {
            j++;
        }
        double s0 = 0, s1 = p.length;
        SegEnd e0 = SegEnd::Base, e1 = SegEnd::Tip;
        if (k > 0) {
            s0 = refine(p.length * k / n, p.length * (k - 1) / n, &e0);
        }
        if (j < n) {
            s1 = refine(p.length * j / n, p.length * (j + 1) / n, &e1);
        }
        va.run.emplace_back(s0, s1);
        va.ends.emplace_back(e0, e1);
        k = j + 1;
    }
    va.runs = static_cast<int>(va.run.size());
    if (va.runs == 0) {
        return va;
    }
    va.s_lo = va.run.front().first;
    va.s_hi = va.run.back().second;
    // Range along the axis is convex: max at a run end, min at a run end or at the foot.
    const double s_foot = dot(r.o - p.base, p.v);
    va.r1 = std::numeric_limits<double>::infinity();
    va.r2 = -1;
    for (size_t k = 0; k < va.run.size(); k++) {
        const double ss[2] = {va.run[k].first, va.run[k].second};
        const SegEnd ee[2] = {va.ends[k].first, va.ends[k].second};
        for (int q = 0; q < 2; q++) {
            const double rr = norm(p.at(ss[q]) - r.o);
            if (rr < va.r1) {
                va.r1 = rr;
                va.s_r1 = ss[q];
                va.r1_end = ee[q];
                va.r1_at_foot = false;
            }
            if (rr > va.r2) {
                va.r2 = rr;
                va.s_r2 = ss[q];
                va.r2_end = ee[q];
            }
        }
        if (s_foot > ss[0] && s_foot < ss[1]) {
            const double rr = norm(p.at(s_foot) - r.o);
            if (rr <= va.r1) {
                va.r1 = rr;
                va.s_r1 = s_foot;
                va.r1_end = SegEnd::None;
                va.r1_at_foot = true;
            }
        }
    }
    return va;
}

double inplane_alpha_deg(const PoleGeom &p, double bearing_world_deg)
{
    const double b = sim_d2r(bearing_world_deg);
    const double vr = p.v.x * std::cos(b) + p.v.y * std::sin(b);
    return sim_r2d(std::atan2(-vr, p.v.z));
}

double paper_alpha_gt_deg(const PoleGeom &p, const RadarPose &r)
{
    const double H = r.o.z;
    const double s_h = H / p.v.z;
    if (s_h > p.length) {
        return std::numeric_limits<double>::quiet_NaN();
    }
    const V3 ph = p.at(s_h);
    const double r1 = norm(ph - r.o);
    const double r2 = norm(p.base - r.o);
    return sim_r2d(std::atan((std::sqrt(std::max(0.0, r2 * r2 - H * H)) - r1) / H));
}

} // namespace sl
