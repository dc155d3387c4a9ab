#pragma once
// The synthetic station (SPEC section 7): a box resting on a turntable disc with a floor below,
// seen by a tilted depth camera, rendered by ray casting with a sensor noise model. It backs
// `boxd synth` and the simulated camera driver, so it is a library function, not CLI code.

#include <cstdint>
#include <optional>
#include <vector>

#include "drivers/sim/sensor_noise.h"
#include "pipeline/core/result.h"
#include "pipeline/io/session.h"

namespace boxd {

// NoiseModel, NoiseModelName() and ParseNoiseModel() live in pipeline/sensor_noise.h.

// The shapes of synthetic objects (synthetic_objects.h builds them).
enum class SyntheticShape {
    kBox,            // length x width x height, with the real-parcel features below
    kCylinder,       // a tube standing: diameter = length = width
    kLyingCylinder,  // a tube on its side along the length: diameter = width = height
    kLShape,         // the length x width footprint without one quarter, full height
    kBag,            // a soft bag: a well rounded, bulging length x width x height core
    kPrism,          // a triangular prism lying on a face: length x width base, ridge on top
    kWedge,          // a wedge lying on a face: its ridge above the -width edge (a right angle)
    kFrustum,        // a tapered carton: length x width base, each side taper_m in at the top
    kPyramid,        // a pyramid on its length x width base, apex above its centre
    kSack,           // a sack bulging low, its bottom overhanging the table (shape_meshes.h)
    kLyingBottle,    // a bottle on its side along the length: diameter = width = height
    kChamfered,      // a carton on a base chamfered by taper_m
    kBoxOnBox,       // a small carton standing off centre on a larger one
    kHandle,         // a carton with a carrying strap looped above its top
};

// An object on the table and where it stands at pose 0, in the table frame (metres, degrees).
// The ideal box (a kBox without features) is rendered exactly; every other object as a mesh.
struct SyntheticBox {
    double length_m = 0.455;
    double width_m = 0.33;
    double height_m = 0.46;
    double offset_x_m = 0.0;  // centre of the footprint relative to the axis, table frame
    double offset_y_m = 0.0;
    double yaw_deg = 0.0;  // rotation of the object about the table axis at pose 0
    SyntheticShape shape = SyntheticShape::kBox;
    // Real-parcel features of a box.
    double edge_radius_m = 0.0;      // rounded edges and corners
    double bulge_m = 0.0;            // each side face bulges out by this much at its middle
    double bulge_top_m = 0.0;        // the top face, likewise
    double strap_thickness_m = 0.0;  // a band over the top and down both ends (along the length)
    double strap_width_m = 0.025;
    double label_thickness_m = 0.0;  // a label on the +width side
    double flap_deg = 0.0;           // a top flap hinged at the +length top edge, this far open
    double taper_m = 0.0;            // a frustum's side comes in by this much from base to top; a
                                     // chamfered carton's base by this much at 45 degrees

    // Returns true for a box without features.
    bool IsIdealBox() const {
        return shape == SyntheticShape::kBox && edge_radius_m == 0.0 && bulge_m == 0.0 &&
               bulge_top_m == 0.0 && strap_thickness_m == 0.0 && label_thickness_m == 0.0 &&
               flap_deg == 0.0;
    }
};

// The camera placement: it looks at a point on the axis `aim_height_m` above the table top,
// from `distance_m` away, `elevation_deg` above the table plane, with no roll. The defaults put
// the table axis at (0, -0.87, -0.5) in the camera frame, the table centre at about
// (0, 0.22, 1.13) m, and keep a 0.46 m tall box and most of the disc in a 640x480 f=570 view.
struct SyntheticCameraPose {
    double distance_m = 1.0;
    double elevation_deg = 30.0;
    double aim_height_m = 0.25;
};

struct SyntheticStationConfig {
    SyntheticBox box;
    SyntheticCameraPose camera_pose;
    CameraIntrinsics camera;         // 640x480, f = 570 by default
    double disc_radius_m = 0.40;     // turntable disc
    double disc_thickness_m = 0.03;  // visible rim of the disc
    double floor_drop_m = 0.10;      // floor (bench) below the table top
    NoiseModel noise = NoiseModel::kKinect;
    // Optional: replaces DefaultSensorNoise(noise) (e.g. tests that switch one artefact off).
    std::optional<SensorNoiseParams> sensor_noise;
    std::uint64_t seed = 1;

    // Errors of the real station that the recorded session does not know about.
    double angle_error_deg = 0.3;  // sigma of the per-pose turntable angle error
    // Magnitudes of the centre error and the axis tilt in the recorded calibration.
    double calib_center_error_m = 0.003;
    double calib_axis_error_deg = 0.3;
    double true_depth_offset_m = 0.0;  // sensor bias: raw z = true z - offset (scale 1)
    // The recorded depth offset minus the true one (signed). 0 (the default) records the true
    // offset, i.e. a station whose depth was already corrected; -true_depth_offset_m records 0,
    // a station that never learnt of its sensor's bias.
    double calib_depth_offset_error_m = 0.0;
    // The lens: the true focal lengths are this many per cent longer than `camera`'s, which the
    // session records (a factory calibration a per cent off).
    double focal_error_pct = 0.0;
    // Optional: the box is pushed by (dx, dy) on the table top and turned by dyaw from this pose
    // on (for OBJECT_MOVED tests).
    std::optional<int> moved_at_pose;
    double moved_dx_m = 0.05, moved_dy_m = 0.0, moved_dyaw_deg = 10.0;
    // More objects standing on the table (a second parcel: MULTIPLE_OBJECTS tests).
    std::vector<SyntheticBox> extra_objects;
    // Optional: a hand reaches into the measuring volume in this pose only.
    std::optional<int> intruder_pose;
    // Material dropout: the objects' surface between these heights above the table is of a
    // material that returns too little of the sensor's light (matte black, an absorbing tape) and
    // reads no depth at all. Equal heights: none.
    double dark_from_m = 0.0, dark_to_m = 0.0;

    // Returns an error naming the first invalid field, or Ok.
    Status Validate() const;
};

// The true geometry of the station, derived from a config (also what the simulated camera uses).
struct SyntheticScene {
    SyntheticStationConfig config;
    SensorNoiseParams noise;                  // config.sensor_noise or the noise model's default
    StationCalibration true_calibration;      // exact centre/axis/depth offset
    StationCalibration recorded_calibration;  // what the session claims (with the injected errors)
};

// Returns the scene of `config` (the calibration errors are drawn from config.seed).
SyntheticScene MakeSyntheticScene(const SyntheticStationConfig& config);

// Returns one raw depth frame of `scene` with the table turned by `true_angle_rad` (ccw, the
// actual angle including any angle error), with the config's noise drawn from `frame_seed`.
// Deterministic for the same inputs.
DepthImage RenderDepthFrame(const SyntheticScene& scene, double true_angle_rad,
                            std::uint64_t frame_seed, int pose_index = 0);

// Returns the seed of the fixed-pattern field (SensorNoiseParams::fixed_pattern_m) of a session
// rendered with `seed`: the same in every frame.
std::uint64_t SyntheticFixedPatternSeed(std::uint64_t seed);

// Returns the noise seed of frame `frame` of pose `pose` in a session rendered with `seed`.
std::uint64_t SyntheticFrameSeed(std::uint64_t seed, int pose, int frame);

// Returns the true table angle (degrees) of pose `pose` commanded to `commanded_deg`: the
// commanded angle plus a seeded N(0, angle_error_deg) error (none for pose 0).
double SyntheticTrueAngleDeg(const SyntheticStationConfig& config, int pose, double commanded_deg);

// Returns the object's true size as a session reports it: the smallest cuboid standing on the
// table that it fits in (length >= width).
BoxDimensions SyntheticGroundTruth(const SyntheticBox& box);

// Returns a whole session: `poses` poses evenly spaced over 360 degrees, `frames` raw frames
// each, the recorded calibration, and the box's true size as ground truth. Poses render on two
// threads; the result does not depend on it.
Result<Session> RenderSyntheticSession(const SyntheticStationConfig& config, int poses, int frames);

// Returns a whole session whose poses stand at the commanded angles `angles_deg` (1..360 of
// them, any spacing).
Result<Session> RenderSyntheticSession(const SyntheticStationConfig& config,
                                       const std::vector<double>& angles_deg, int frames);

}  // namespace boxd
