#pragma once
// The synthetic station's geometry: where the camera sits in the table frame, where the box
// stands at a table angle, and ray casting of the scene: the ideal box, disc (top and rim) and
// floor exactly, every other object as a triangle mesh (MeshRayCaster).

#include <Eigen/Core>
#include <memory>

#include "drivers/sim/mesh_ray_caster.h"
#include "drivers/sim/synthetic_station.h"

namespace boxd {

// The camera placement in the table frame (origin where the axis meets the table top, +z up).
struct SyntheticCameraFrame {
    Eigen::Matrix3d table_to_camera;  // rows: the camera's x, y, z axes in table coordinates
    Eigen::Vector3d position_m;       // camera centre in table coordinates
};

// Returns the camera frame of `pose`: on the table's -y side, looking at (0, 0, aim_height_m),
// image x parallel to the table plane (no roll).
SyntheticCameraFrame MakeSyntheticCameraFrame(const SyntheticCameraPose& pose);

// The box footprint placement in the table frame at one table angle.
struct SyntheticBoxPlacement {
    Eigen::Vector2d center_m;  // box centre on the table plane
    double yaw_rad = 0.0;      // rotation of the box's length axis from table x, ccw
};

// Returns where the box stands when the table has turned by `table_angle_rad` (ccw), including
// the displacement of config.moved_at_pose when `pose_index` has reached it.
SyntheticBoxPlacement PlaceSyntheticBox(const SyntheticStationConfig& config,
                                        double table_angle_rad, int pose_index);

// What one camera ray hits first.
struct SyntheticRayHit {
    double z_m = 0.0;            // z-depth (along the optical axis); 0 = nothing hit
    double cos_incidence = 1.0;  // |cos| of the angle between the ray and the surface normal
    bool object = false;         // the hit is on an object standing on the table
    double height_m = 0.0;       // the hit's height above the table top
    Eigen::Vector3d point = Eigen::Vector3d::Zero();  // the hit, table frame
};

// Exact ray caster of the scene at one table angle. Cheap to build; Cast() is thread-safe.
class SyntheticRayCaster {
public:
    SyntheticRayCaster(const SyntheticStationConfig& config, double table_angle_rad,
                       int pose_index);

    // Returns the first hit of the ray through pixel coordinates (u, v) (pixel centres at
    // integers, as in the intrinsics).
    SyntheticRayHit Cast(double u, double v) const;

    // Returns whether an object stands between `from` and `to` (table frame; `to` itself and the
    // last `margin_m` before it excluded, so a surface point does not block itself).
    bool Blocked(const Eigen::Vector3d& from, const Eigen::Vector3d& to, double margin_m) const;

    // The camera centre, and its x axis (the baseline's direction), table frame.
    const Eigen::Vector3d& Origin() const { return origin_; }
    Eigen::Vector3d CameraX() const { return camera_to_table_.col(0); }

private:
    CameraIntrinsics camera_;
    double inv_fx_ = 1.0, inv_fy_ = 1.0;
    Eigen::Matrix3d camera_to_table_;       // columns: camera axes in table coordinates
    Eigen::Vector3d origin_;                // camera centre, table frame
    Eigen::Vector3d origin_box_;            // camera centre, box frame
    Eigen::Vector2d box_center_;            // the box's centre on the table, table frame
    double box_cos_ = 1.0, box_sin_ = 0.0;  // table -> box frame rotation about z
    Eigen::Vector3d to_box_center_;         // camera centre -> box centre, table frame
    double box_radius_sq_ = 0.0;            // squared radius of the box's bounding sphere
    Eigen::Vector3d box_half_;              // half extents; box frame z runs 0..height
    double disc_radius_ = 0.0, disc_thickness_ = 0.0, floor_drop_ = 0.0;
    bool ideal_box_ = true;                        // the main object is the exact box above
    std::shared_ptr<const MeshRayCaster> meshes_;  // every other object, table frame (or null)
};

}  // namespace boxd
