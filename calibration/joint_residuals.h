#pragma once
// The residual model of the joint calibration problem (joint_refinement.h): where a pixel lies in
// the table frame and on the reference box for a state, and the Ceres cost functors of the table
// top and the box faces. Included by joint_refinement.cpp only.

#include <ceres/ceres.h>
#include <ceres/rotation.h>

#include <Eigen/Core>
#include <cmath>
#include <vector>

#include "pipeline/io/session.h"

namespace boxd::joint {

// Point groups: the table top and the five visible faces of the box.
enum Group { kTable = 0, kPlusU, kMinusU, kPlusV, kMinusV, kTop, kGroups };

// One pose's pixels with their back-projection ray already turned into the base frame:
// base * p = a * z + t0 with a = lateral / focal_scale + axial, where z is the corrected depth:
// the ray's lateral part (x/z, y/z from the recorded fx, fy) shrinks as the focal length grows,
// the optical axis does not.
struct PosePoints {
    std::vector<Eigen::Vector3d> a;  // lateral part, base frame
    std::vector<double> raw_z;
    Eigen::Vector3d axial = Eigen::Vector3d::UnitZ();  // the optical axis, base frame
};

// Table coordinates q of pixel k of `pts` (see JointState), and when `ray` is given, dq/dz: how
// the point moves per metre of corrected depth (the viewing ray in table coordinates).
template <typename T>
void TablePoint(const PosePoints& pts, std::size_t k, const Eigen::Vector3d& t0, const T* frame,
                const T* depth, T* q, T* ray = nullptr) {
    const T z = T(pts.raw_z[k]) * depth[1] + depth[0];
    const Eigen::Vector3d& l = pts.a[k];
    const Eigen::Vector3d& o = pts.axial;
    const T inv_focal = T(1.0) / depth[2];
    const T a[3] = {T(l.x()) * inv_focal + T(o.x()), T(l.y()) * inv_focal + T(o.y()),
                    T(l.z()) * inv_focal + T(o.z())};
    const T d[3] = {a[0] * z + T(t0.x()) - frame[2], a[1] * z + T(t0.y()) - frame[3],
                    a[2] * z + T(t0.z()) - frame[4]};
    const T inverse_tilt[3] = {-frame[0], -frame[1], T(0.0)};
    ceres::AngleAxisRotatePoint(inverse_tilt, d, q);
    if (ray != nullptr) ceres::AngleAxisRotatePoint(inverse_tilt, a, ray);
}

// Box coordinates (u along the length, v along the width) of table point q seen at table
// angle `angle`: the table turned by +angle about z, so the point sat at R(-angle) q at pose 0.
template <typename T>
void BoxPoint(const T* q, const T* box, const T* angle, T* u, T* v) {
    using std::cos;
    using std::sin;
    const T ca = cos(angle[0]), sa = sin(angle[0]);
    const T x0 = ca * q[0] + sa * q[1] - box[0];
    const T y0 = -sa * q[0] + ca * q[1] - box[1];
    const T cb = cos(box[2]), sb = sin(box[2]);
    *u = cb * x0 + sb * y0;
    *v = -sb * x0 + cb * y0;
}

// The in-plane part of BoxPoint for a direction (no translation): how (u, v) move with q.
template <typename T>
void BoxDirection(const T* dq, const T* box, const T* angle, T* du, T* dv) {
    using std::cos;
    using std::sin;
    const T ca = cos(angle[0]), sa = sin(angle[0]);
    const T x0 = ca * dq[0] + sa * dq[1];
    const T y0 = -sa * dq[0] + ca * dq[1];
    const T cb = cos(box[2]), sb = sin(box[2]);
    *du = cb * x0 + sb * y0;
    *dv = -sb * x0 + cb * y0;
}

// How the signed distance outside face `group` changes per metre along the viewing ray.
template <typename T>
T FaceSlope(int group, const T& du, const T& dv, const T& dz) {
    switch (group) {
        case kPlusU:
            return du;
        case kMinusU:
            return -du;
        case kPlusV:
            return dv;
        case kMinusV:
            return -dv;
        default:
            return dz;
    }
}

// A residual in depth along the viewing ray: the distance `r` from the surface over how fast it
// changes with depth. The sensor's noise is in depth: a distance residual carries it times
// |slope|, which the focal scale, the tilt and the box's yaw change, so least squares on
// distances would buy smaller residuals by turning rays grazing (a bias of the order of σ²: a
// tenth of a per cent of focal scale, a millimetre of offset, at 2 mm of noise). In depth the
// noise does not depend on the parameters; how large it is at each incidence is the data's to
// say (DepthWeights). Rays within kMinSlope of grazing are held at that rate.
constexpr double kMinSlope = 0.2;

template <typename T>
T DepthResidual(const T& r, const T& slope) {
    using std::abs;
    T rate = abs(slope);
    if (rate < T(kMinSlope)) rate = T(kMinSlope);
    return r / rate;
}

// Signed distance outside face `group` of the reference box.
template <typename T>
T FaceDistance(int group, const T& u, const T& v, const T& z, const BoxDimensions& ref) {
    const double hl = 0.5 * ref.length_m, hw = 0.5 * ref.width_m;
    switch (group) {
        case kPlusU:
            return u - T(hl);
        case kMinusU:
            return -u - T(hl);
        case kPlusV:
            return v - T(hw);
        case kMinusV:
            return -v - T(hw);
        default:
            return z - T(ref.height_m);
    }
}

// Table residual. A pixel with back-projection ray a (camera frame, turned into the base
// table frame: base · p = a z + t0) and raw depth z_raw lies, with the state's depth correction
// z = z_raw · scale + offset, at
//     q = R(tilt)ᵀ (a z + t0 − centre)
// in the corrected table frame (TablePoint). A point of the table top satisfies q_z = 0, so
//     r = w · q_z / |∂q_z/∂z|,
// its depth along the ray (DepthResidual) weighed by w = 1 / the depth noise of points seen at
// a like incidence (DepthWeights in joint_refinement.cpp): table and face residuals are weighed
// by their own noise, not by how many points each group has.
struct TableCost {
    const PosePoints* pts;
    std::vector<int> idx;
    std::vector<double> weight;  // per point: 1 / its depth noise
    Eigen::Vector3d t0;

    template <typename T>
    bool operator()(const T* frame, const T* depth, T* r) const {
        for (std::size_t i = 0; i < idx.size(); ++i) {
            const auto k = static_cast<std::size_t>(idx[i]);
            T q[3], ray[3];
            TablePoint(*pts, k, t0, frame, depth, q, ray);
            r[i] = T(weight[i]) * DepthResidual(q[2], ray[2]);
        }
        return true;
    }
};

// Face residual. A pixel of pose k assigned to face f of the reference box lies at q (as for
// the table). Turned back by the table's angle α_k about the axis, it sat at R(−α_k) q at pose 0;
// in box coordinates (u along the length, v along the width, the box centred at (b_x, b_y) and
// turned by β),
//     (u, v) = R(−β) ( R(−α_k) q_xy − b )      (BoxPoint).
// A point on face f of a box of the REFERENCE size L × W × H satisfies the face's plane
// equation, and the residual is its signed distance outside that face (FaceDistance):
//     d = ±u − L/2,  ±v − W/2  or  q_z − H   (side faces, top),
// and, as for the table, the residual is its depth along the ray, r = w · d / |∂d/∂z|.
// Because L, W, H are fixed, the depth offset and scale that stretch the cloud are observable:
// no other state makes all faces meet the known box.
struct FaceCost {
    const PosePoints* pts;
    std::vector<int> idx;
    std::vector<double> weight;  // per point: 1 / its depth noise
    Eigen::Vector3d t0;
    int group;
    BoxDimensions ref;

    template <typename T>
    bool operator()(const T* frame, const T* depth, const T* box, const T* angle, T* r) const {
        for (std::size_t i = 0; i < idx.size(); ++i) {
            const auto k = static_cast<std::size_t>(idx[i]);
            T q[3], ray[3], u, v, du, dv;
            TablePoint(*pts, k, t0, frame, depth, q, ray);
            BoxPoint(q, box, angle, &u, &v);
            BoxDirection(ray, box, angle, &du, &dv);
            r[i] = T(weight[i]) * DepthResidual(FaceDistance(group, u, v, q[2], ref),
                                                FaceSlope(group, du, dv, ray[2]));
        }
        return true;
    }
};

}  // namespace boxd::joint
