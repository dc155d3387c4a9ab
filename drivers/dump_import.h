#pragma once
// A Kinect dump recorded on a station (fakenect-record running while the turntable stops at
// each pose) turned into a boxd session, so that it can be measured, replayed and shared like a
// recorded one (`boxd import-dump`).
//
// The dump does not say where the table stood: the poses are found in the depth itself. A pixel
// changed between two frames when its raw disparity moved by more than `motion_levels` steps.
// Between two frames of a still scene that happens only to the noisiest pixels, about the same
// share from frame to frame; a turning parcel changes far more (its outline and its faces move).
// The dump's noise floor is that share between its quietest consecutive frames: the stops given
// hold at least stops x (frames_per_pose - 1) still pairs, and the floor is the percentile at half
// their share. A frame belongs to the still stretch it is in while it differs from the stretch's
// first frame by at most `motion_factor` times the floor. Each stretch of at least
// `frames_per_pose` frames is one pose, and its middle frames are kept. The table's angles come
// from the user: `poses` evenly spaced stops over a turn, or the `angles_deg` of the stops; the
// frames before the first stop or after the last (the parcel put down, the table going home) are
// left out with `first_frame` and `last_frame`.

#include <filesystem>
#include <string>
#include <vector>

#include "pipeline/core/camera.h"
#include "pipeline/core/result.h"
#include "pipeline/core/station_calibration.h"
#include "pipeline/io/session.h"

namespace boxd {

struct DumpImportOptions {
    int poses = 0;                   // evenly spaced stops over 360 degrees, or 0 with angles_deg
    std::vector<double> angles_deg;  // the stops' table angles in recording order
    int frames_per_pose = 5;         // frames kept per pose (the stretch's middle ones)
    int first_frame = 0;             // the dump's depth frames used: first_frame..last_frame
    int last_frame = -1;             // (0-based; -1: to the end)
    int motion_levels = 2;           // a pixel changed: its disparity moved by more steps
    double motion_factor = 3.0;      // a frame moved: this many times the noise floor changed

    // Returns an error naming the first invalid option, or Ok.
    Status Validate() const;
    // Returns the angles of the poses: angles_deg, or `poses` evenly spaced from 0.
    std::vector<double> Angles() const;
};

// A run of frames in one place: dump depth frames first .. first + count - 1 (0-based).
struct StillStretch {
    int first = 0;
    int count = 0;
};

// The station the session is for: what a recorded session carries besides the frames.
struct DumpStation {
    CameraIntrinsics camera;  // its depth_unit_m is the session's
    StationCalibration calibration;
    TurntableDirection direction = TurntableDirection::kCcw;
};

// What an import found and made.
struct DumpImport {
    Session session;
    std::vector<StillStretch> stretches;  // every still stretch, long enough or not
    int depth_frames = 0;
    double noise_floor = 0.0;  // the share of pixels changed between two still frames
    double threshold = 0.0;    // the share above which a frame moved
};

// Reads the dump in `dir` (CheckDump first: CAMERA_ERROR for a broken one) and returns the
// session; INVALID_INPUT when the count of still stretches long enough differs from the poses
// asked for (the message lists the stretches found).
Result<DumpImport> ImportDump(const std::filesystem::path& dir, const DumpImportOptions& options,
                              const DumpStation& station);

// Returns the share of the pixels read in both raw frames whose disparity differs by more than
// `levels` steps (1 when fewer than a thousand pixels are read in both).
double ChangedFraction(const std::vector<std::uint16_t>& a, const std::vector<std::uint16_t>& b,
                       int levels);

}  // namespace boxd
