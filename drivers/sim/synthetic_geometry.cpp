#include "drivers/sim/synthetic_geometry.h"

#include <cmath>
#include <limits>

#include "drivers/sim/synthetic_objects.h"

namespace boxd {

namespace {

constexpr double kDegToRad = M_PI / 180.0;
constexpr double kInf = std::numeric_limits<double>::infinity();

// Ray/box slab test (Kay and Kajiya 1986) in the box frame: the box spans [-hx, hx] x [-hy, hy]
// x [0, hz2]. Returns the entry distance (inf if missed) and sets `cos_axis` to the ray
// direction's component along the entry face's normal.
double IntersectBox(const double o[3], const double d[3], const double lo[3], const double hi[3],
                    double& entry_component) {
    double t_near = -kInf, t_far = kInf;
    int axis = -1;
    for (int i = 0; i < 3; ++i) {
        if (std::abs(d[i]) < 1e-15) {
            if (o[i] < lo[i] || o[i] > hi[i]) return kInf;
            continue;
        }
        const double inv = 1.0 / d[i];
        double t0 = (lo[i] - o[i]) * inv;
        double t1 = (hi[i] - o[i]) * inv;
        if (t0 > t1) std::swap(t0, t1);
        if (t0 > t_near) {
            t_near = t0;
            axis = i;
        }
        if (t1 < t_far) t_far = t1;
        if (t_near > t_far) return kInf;
    }
    if (axis < 0 || t_near <= 0.0) return kInf;  // the camera is never inside the box
    entry_component = d[axis];
    return t_near;
}

}  // namespace

SyntheticCameraFrame MakeSyntheticCameraFrame(const SyntheticCameraPose& pose) {
    const double el = pose.elevation_deg * kDegToRad;
    const double c = std::cos(el), s = std::sin(el);
    SyntheticCameraFrame f;
    f.position_m =
        Eigen::Vector3d(0.0, -pose.distance_m * c, pose.aim_height_m + pose.distance_m * s);
    const Eigen::Vector3d forward(0.0, c, -s);          // towards the aim point
    const Eigen::Vector3d right(1.0, 0.0, 0.0);         // parallel to the table plane: no roll
    const Eigen::Vector3d down = forward.cross(right);  // right-handed x right, y down, z forward
    f.table_to_camera.row(0) = right.transpose();
    f.table_to_camera.row(1) = down.transpose();
    f.table_to_camera.row(2) = forward.transpose();
    return f;
}

SyntheticBoxPlacement PlaceSyntheticBox(const SyntheticStationConfig& config,
                                        double table_angle_rad, int pose_index) {
    const SyntheticBox& b = config.box;
    Eigen::Vector2d offset(b.offset_x_m, b.offset_y_m);
    double yaw = b.yaw_deg * kDegToRad;
    if (config.moved_at_pose && pose_index >= *config.moved_at_pose) {
        // The box slid on the table top: the push is in the table's own (turning) frame.
        offset += Eigen::Vector2d(config.moved_dx_m, config.moved_dy_m);
        yaw += config.moved_dyaw_deg * kDegToRad;
    }
    const double c = std::cos(table_angle_rad), s = std::sin(table_angle_rad);
    SyntheticBoxPlacement p;
    p.center_m = Eigen::Vector2d(c * offset.x() - s * offset.y(), s * offset.x() + c * offset.y());
    p.yaw_rad = yaw + table_angle_rad;
    return p;
}

SyntheticRayCaster::SyntheticRayCaster(const SyntheticStationConfig& config, double table_angle_rad,
                                       int pose_index)
    : camera_(config.camera),
      disc_radius_(config.disc_radius_m),
      disc_thickness_(config.disc_thickness_m),
      floor_drop_(config.floor_drop_m) {
    // The rays leave through the true lens, whose focal lengths the session may not record.
    camera_.fx *= 1.0 + config.focal_error_pct / 100.0;
    camera_.fy *= 1.0 + config.focal_error_pct / 100.0;
    const SyntheticCameraFrame frame = MakeSyntheticCameraFrame(config.camera_pose);
    camera_to_table_ = frame.table_to_camera.transpose();
    origin_ = frame.position_m;
    const SyntheticBoxPlacement place = PlaceSyntheticBox(config, table_angle_rad, pose_index);
    box_center_ = place.center_m;
    box_cos_ = std::cos(place.yaw_rad);
    box_sin_ = std::sin(place.yaw_rad);
    const Eigen::Vector3d rel(origin_.x() - place.center_m.x(), origin_.y() - place.center_m.y(),
                              origin_.z());
    origin_box_ = Eigen::Vector3d(box_cos_ * rel.x() + box_sin_ * rel.y(),
                                  -box_sin_ * rel.x() + box_cos_ * rel.y(), rel.z());
    box_half_ = Eigen::Vector3d(config.box.length_m / 2.0, config.box.width_m / 2.0,
                                config.box.height_m / 2.0);
    to_box_center_ =
        Eigen::Vector3d(place.center_m.x(), place.center_m.y(), box_half_.z()) - origin_;
    box_radius_sq_ = box_half_.squaredNorm() * (1.0 + 1e-9);
    inv_fx_ = 1.0 / camera_.fx;
    inv_fy_ = 1.0 / camera_.fy;
    ideal_box_ = config.box.IsIdealBox();
    if (auto mesh = PlacedObjectMeshes(config, table_angle_rad, pose_index)) {
        meshes_ = std::make_shared<const MeshRayCaster>(*mesh);
    }
}

SyntheticRayHit SyntheticRayCaster::Cast(double u, double v) const {
    // With the camera-frame direction's z set to 1, the ray parameter is the z-depth itself.
    const double cx = (u - camera_.cx) * inv_fx_, cy = (v - camera_.cy) * inv_fy_;
    const Eigen::Vector3d d =
        camera_to_table_.col(0) * cx + camera_to_table_.col(1) * cy + camera_to_table_.col(2);
    const double d_norm_sq = cx * cx + cy * cy + 1.0;
    const double d_norm = std::sqrt(d_norm_sq);
    const double ox = origin_.x(), oy = origin_.y(), oz = origin_.z();

    double best_t = kInf;
    double best_component = 0.0;  // the direction's component along the hit surface's normal
    bool object = false;

    // Box (solid): the slab test in the box frame.
    const double ob[3] = {origin_box_.x(), origin_box_.y(), origin_box_.z()};
    const double db[3] = {box_cos_ * d.x() + box_sin_ * d.y(), -box_sin_ * d.x() + box_cos_ * d.y(),
                          d.z()};
    const double lo[3] = {-box_half_.x(), -box_half_.y(), 0.0};
    const double hi[3] = {box_half_.x(), box_half_.y(), 2.0 * box_half_.z()};
    double component = 0.0;
    const double t_box = ideal_box_ ? IntersectBox(ob, db, lo, hi, component) : kInf;
    if (t_box < best_t) {
        best_t = t_box;
        best_component = component;
        object = true;
    }
    // Mesh objects. The ray parameter is the z-depth here too: `d` is not normalised.
    MeshRayCaster::Hit mesh_hit;
    if (meshes_ && meshes_->Intersect(origin_, d, best_t, mesh_hit) && mesh_hit.t < best_t) {
        best_t = mesh_hit.t;
        best_component = mesh_hit.cos_incidence * d_norm;
        object = true;
    }

    if (d.z() < 0.0) {
        // Disc top (z = 0), seen from above.
        const double inv_dz = 1.0 / d.z();
        const double t_top = -oz * inv_dz;
        const double x = ox + t_top * d.x(), y = oy + t_top * d.y();
        if (t_top > 0.0 && t_top < best_t && x * x + y * y <= disc_radius_ * disc_radius_) {
            best_t = t_top;
            best_component = d.z();
            object = false;
        }
        // Floor (z = -floor_drop).
        const double t_floor = (-floor_drop_ - oz) * inv_dz;
        if (t_floor > 0.0 && t_floor < best_t) {
            best_t = t_floor;
            best_component = d.z();
            object = false;
        }
    }

    // Disc rim: the outside of the cylinder x^2 + y^2 = R^2 for -thickness <= z <= 0.
    const double a = d.x() * d.x() + d.y() * d.y();
    const double b = ox * d.x() + oy * d.y();
    const double c = ox * ox + oy * oy - disc_radius_ * disc_radius_;
    const double disc = b * b - a * c;
    if (a > 1e-15 && c > 0.0 && disc >= 0.0) {
        const double t_rim = (-b - std::sqrt(disc)) / a;
        const double z = oz + t_rim * d.z();
        if (t_rim > 0.0 && t_rim < best_t && z <= 0.0 && z >= -disc_thickness_) {
            best_t = t_rim;
            const double x = ox + t_rim * d.x(), y = oy + t_rim * d.y();
            best_component = (x * d.x() + y * d.y()) / disc_radius_;
            object = false;
        }
    }

    SyntheticRayHit hit;
    if (best_t < kInf) {
        hit.z_m = best_t;
        hit.cos_incidence = std::min(1.0, std::abs(best_component) / d_norm);
        hit.object = object;
        hit.height_m = oz + best_t * d.z();
        hit.point = origin_ + best_t * d;
    }
    return hit;
}

bool SyntheticRayCaster::Blocked(const Eigen::Vector3d& from, const Eigen::Vector3d& to,
                                 double margin_m) const {
    const Eigen::Vector3d d = to - from;
    const double length = d.norm();
    if (!(length > margin_m)) return false;
    const double t_max = 1.0 - margin_m / length;  // the segment runs over t in (0, 1)
    if (ideal_box_) {
        const Eigen::Vector3d rel(from.x() - box_center_.x(), from.y() - box_center_.y(), from.z());
        const double ob[3] = {box_cos_ * rel.x() + box_sin_ * rel.y(),
                              -box_sin_ * rel.x() + box_cos_ * rel.y(), rel.z()};
        const double db[3] = {box_cos_ * d.x() + box_sin_ * d.y(),
                              -box_sin_ * d.x() + box_cos_ * d.y(), d.z()};
        const double lo[3] = {-box_half_.x(), -box_half_.y(), 0.0};
        const double hi[3] = {box_half_.x(), box_half_.y(), 2.0 * box_half_.z()};
        double component = 0.0;
        if (IntersectBox(ob, db, lo, hi, component) < t_max) return true;
    }
    MeshRayCaster::Hit hit;
    return meshes_ && meshes_->Intersect(from, d, t_max, hit) && hit.t < t_max;
}

}  // namespace boxd
