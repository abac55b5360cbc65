// SPDX-License-Identifier: MIT
// sim_geom.h: exact geometry of the scene simulator (host only, double precision).
//
// Conventions (sim_scene.h): world x, y horizontal, z up, ground z = 0, world angles CCW
// from +x; the radar's azimuths are clockwise from vehicle forward, so a world bearing b
// (CCW) and a vehicle-frame azimuth a (CW) are related by a = heading - b.
//
// The pole is a cylinder around its axis; what the radar can see of it on one azimuth is
// computed on the AXIS (the "visible segment", MATH.md s.5): the axis points that are
// inside the emission wedge, above the chassis shadow ray -theta(azimuth of the point),
// inside the azimuth window of the beam and not hidden by boxes or other poles. Its range
// extremes are the ground-truth r1, r2; the simulator then adds the cylinder's surface
// (front surface nearer by R / |sin(ray, axis)|, silhouette at the axis range).
#pragma once

#include <cmath>
#include <string>
#include <vector>

#include "sim_scene.h"
#include "sl_board_spec.h"

namespace sl {

constexpr double kSimPi = 3.14159265358979323846;
inline double sim_d2r(double d) { return d * kSimPi / 180.0; }
inline double sim_r2d(double r) { return r * 180.0 / kSimPi; }
/// Angle wrapped to [-180, 180).
double wrap180(double deg);

struct V3 {
    double x = 0, y = 0, z = 0;
};
inline V3 operator+(V3 a, V3 b) { return {a.x + b.x, a.y + b.y, a.z + b.z}; }
inline V3 operator-(V3 a, V3 b) { return {a.x - b.x, a.y - b.y, a.z - b.z}; }
inline V3 operator*(double k, V3 a) { return {k * a.x, k * a.y, k * a.z}; }
inline double dot(V3 a, V3 b) { return a.x * b.x + a.y * b.y + a.z * b.z; }
inline double norm(V3 a) { return std::sqrt(dot(a, a)); }
inline V3 cross(V3 a, V3 b)
{
    return {a.y * b.z - a.z * b.y, a.z * b.x - a.x * b.z, a.x * b.y - a.y * b.x};
}

/// Opening angle theta (deg) of the chassis on an arbitrary vehicle-frame azimuth (deg,
/// clockwise from forward): the same construction as BoardSpec::theta_deg (which only takes
/// azimuth indices). NaN when no chassis edge surrounds the radar on that azimuth.
double chassis_theta_deg(const BoardSpec &b, double az_vehicle_deg);
/// The same, and the horizontal distance from the radar to that grazing edge (m) in
/// `*edge_m` (may be NULL).
double chassis_theta_deg(const BoardSpec &b, double az_vehicle_deg, double *edge_m);

/// A pole prepared for ray work.
struct PoleGeom {
    V3 base;            ///< axis at z = 0
    V3 v;               ///< unit axis, upwards
    V3 lean;            ///< horizontal unit vector of the lean (arbitrary when vertical)
    double length = 0, radius = 0, tan_psi = 0, reflectivity = 1;
    V3 at(double s) const { return base + s * v; }
};
PoleGeom make_pole_geom(const ScenePole &p);

/// An oriented box prepared for slab tests.
struct BoxGeom {
    double cx = 0, cy = 0, c = 1, s = 0, hx = 0.5, hy = 0.5, z0 = 0, z1 = 1, reflectivity = 0;
    /// Nearest entry distance t in (tmin, tmax) of the ray o + t d (d need not be unit);
    /// false when it misses.
    bool hit(V3 o, V3 d, double tmin, double tmax, double *t) const;
};
BoxGeom make_box_geom(const SceneBox &b);

/// Radar pose at one instant (world).
struct RadarPose {
    V3 o;               ///< radar position (z = board radar height)
    double heading_deg = 0; ///< vehicle heading, world CCW
    double t_s = 0;     ///< seconds since the start of the scene
};

/// Pose of the radar at time t (seconds from rotation 0, azimuth 0): constant-speed path.
RadarPose radar_pose_at(const Scene &s, double t_s);

/// Vehicle-frame azimuth (deg, CW from forward) of world point p seen from the radar.
double azimuth_of(const RadarPose &r, V3 p);

/// Why a visible run of the axis ends where it does.
enum class SegEnd {
    None = 0,
    Top,      ///< upper emission bound (+beta)
    Bottom,   ///< lower emission bound (-35 deg)
    Chassis,  ///< the chassis shadow ray (-theta)
    Beam,     ///< the azimuth window of the beam
    Occluded, ///< a box or another pole
    Base,     ///< the pole's foot on the ground is visible (pole outside the shadow)
    Tip,      ///< the pole's top end
};
const char *seg_end_name(SegEnd e);

/// Everything that can hide a point of a pole.
struct Occluders {
    const std::vector<PoleGeom> *poles = nullptr;
    const std::vector<BoxGeom> *boxes = nullptr;
};

/// The visible part of a pole's axis on one azimuth.
struct VisibleAxis {
    int runs = 0;               ///< disjoint visible runs (0: invisible)
    double s_lo = 0, s_hi = 0;  ///< union extent along the axis (m from the base)
    std::vector<std::pair<double, double>> run; ///< each run [s0, s1]
    std::vector<std::pair<SegEnd, SegEnd>> ends; ///< what ends each run (lower s, upper s)
    double r1 = 0, r2 = 0;      ///< min / max axis range over the visible set (m)
    double s_r1 = 0, s_r2 = 0;  ///< where they are
    bool r1_at_foot = false;    ///< r1 is the perpendicular foot (interior minimum)
    SegEnd r1_end = SegEnd::None, r2_end = SegEnd::None; ///< ends where r1, r2 lie
};

/// Emission wedge of the beam: elevations [bottom, top] (deg).
struct Wedge {
    double top_deg = 0, bottom_deg = -35;
};

/// Visible axis of pole `self` (index into occ.poles, -1 if not there) seen from `r` on
/// the azimuth centred at `az_center_deg` (vehicle frame) with window half-width
/// `cutoff_deg` (<= 0: no window). Sampled at `samples` points, every transition refined
/// by bisection to 1e-9 m. Cost: O(samples * occluders).
VisibleAxis visible_axis(const BoardSpec &b, const RadarPose &r, const PoleGeom &p, int self,
                         const Occluders &occ, const Wedge &w, double az_center_deg,
                         double cutoff_deg, int samples = 400);

/// MATH.md s.5: in-plane inclination (deg) of the pole's axis in the vertical half-plane of
/// world bearing `bearing_world_deg`: atan2(-(v . e_r), v . e_z); > 0 = top towards radar.
double inplane_alpha_deg(const PoleGeom &p, double bearing_world_deg);

/// The paper's ground truth (Sec. IV-A, MATH.md s.5): r1 = distance to the axis point at
/// radar height, r2 = distance to the base, alpha_gt = atan((sqrt(r2^2 - H^2) - r1) / H).
/// NaN when the pole does not reach the radar's height.
double paper_alpha_gt_deg(const PoleGeom &p, const RadarPose &r);

} // namespace sl
