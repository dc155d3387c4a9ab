#pragma once
// Registration stage: initial poses from the turntable angles and the ICP edges of the pose graph
// (neighbouring poses and loop closures between non-neighbours, last-to-first included).

#include <Eigen/Geometry>
#include <utility>
#include <vector>

#include "pipeline/core/result.h"
#include "pipeline/registration/icp.h"
#include "pipeline/registration/pose_graph.h"
#include "pipeline/views/registration_cloud.h"

namespace boxd {

struct RegistrationConfig {
    // The coarse cloud's voxel is twice the fine one's, and its min_points a quarter: both
    // start shrinking at the same object size (each stops at its own min_readings voxel).
    RegistrationCloudConfig coarse_cloud{0.012, 8, 2.0, 10, 1000, 0.03, 250};
    RegistrationCloudConfig fine_cloud{0.006, 8, 2.0, 10, 3000, 0.02, 1000};
    // Coarse: wide gate on the sparse cloud; fine: narrow gate on the denser one.
    IcpConfig coarse{.max_correspondence_m = 0.02,
                     .max_iterations = 20,
                     .translation_tolerance_m = 1e-4,
                     .yaw_tolerance_rad = 1e-4,
                     .robust_scale_m = 0.008};
    // The fine stage is point-to-plane only. A point-to-point pull to the nearest sample of a
    // sampled surface has no restoring force along that surface (the offsets to the nearest
    // samples spread over the sampling cell however far the views have slid), so where the
    // surfaces constrain a direction only weakly it holds the motion where it started: at the
    // turntable model, whose centre is the calibration's, millimetres off. Every edge then
    // leans the same way, the views turn about a centre pulled towards the calibrated one, and
    // the box grows or shrinks by a few tenths of a millimetre on every side. The coarse stage
    // keeps the pull: it is what holds a direction no surface fixes (a standing tube's turn)
    // near the model, and the fine stage's weak prior keeps it there.
    IcpConfig fine{.max_correspondence_m = 0.008,
                   .max_iterations = 10,
                   .translation_tolerance_m = 5e-5,
                   .yaw_tolerance_rad = 5e-5,
                   .robust_scale_m = 0.003,
                   .point_to_point_weight = 0.0};
    int max_pose_step = 3;  // pairs up to this many poses apart (cyclically) are aligned ...
    double max_pair_angle_deg = 100.0;  // ... when their turntable angles differ by at most this
    double min_fitness = 0.3;           // an alignment with fewer matched points is not an edge
    double max_rmse_m = 0.006;          // nor one with a larger point-to-plane RMSE
    int threads = 2;

    // Returns an error naming the first invalid field, or Ok.
    Status Validate() const;
};

// Per view: the coarse and the fine registration cloud.
using ViewClouds = RegistrationClouds;

struct EdgeStats {
    int attempted = 0;
    int accepted = 0;
    double mean_rmse_m = 0.0;  // over accepted edges
    // The views (sorted, once each) of the alignments that tested them against a neighbour,
    // accepted or not: that found a side in common, or found the view's top disagreeing with
    // its neighbour's (the object elsewhere). A view in none of them saw other sides than its
    // neighbours, its top where theirs is.
    std::vector<int> tested_views;
};

// Returns node k's initial pose: the rotation by -angle_k (relative to pose 0) about the axis,
// which maps view k's points back into the frame of pose 0.
std::vector<Se2> TurntablePoses(const std::vector<double>& table_angles_rad);

// The poses of a session (or of a capture's plan) in their order around the turn: each pose's
// rank when its angle, wrapped into one turn, is sorted (ties in pose order). A capture may
// take its poses in any order (a sweep forwards, backwards, or the coverage order's passes);
// which views are neighbours depends only on where they stand.
class TurnOrder {
public:
    explicit TurnOrder(const std::vector<double>& table_angles_rad);
    int size() const { return static_cast<int>(rank_.size()); }
    int RankOf(int pose) const { return rank_[static_cast<std::size_t>(pose)]; }
    // The pose `steps` places after `pose` around the turn (negative: before), cyclically.
    int Neighbour(int pose, int steps) const;

private:
    std::vector<int> rank_, at_;
};

// Returns the views i < j that view j is aligned with: at most max_pose_step places apart
// around the turn of the planned poses `plan_rad` (cyclically: the first ones with the last
// ones), turntable angles at most max_pair_angle_deg apart. For a session captured in order
// around the turn that is the cyclic index distance. Reads only the angles, so a capture can ask
// as soon as view j arrives.
std::vector<int> PairedEarlierViews(int j, const TurnOrder& order,
                                    const std::vector<double>& plan_rad,
                                    const RegistrationConfig& config);

// Returns every pair (i, j), i < j, of PairedEarlierViews, sorted.
std::vector<std::pair<int, int>> ViewPairs(const std::vector<double>& table_angles_rad,
                                           const RegistrationConfig& config);

// Marks the loop closures among `edges` of the session at `table_angles_rad`: every edge but
// those between neighbours around the turn, and of those the one that closes the loop (pose 0
// with the later captured of its two neighbours). Robust losses go on loop closures.
void MarkLoopClosures(std::vector<PoseEdge>& edges, const std::vector<double>& table_angles_rad);

// One view's registration clouds with their search indices, built once.
struct ViewTargets {
    ViewTargets(const ViewClouds& clouds, const RegistrationConfig& config);
    IcpTarget coarse, fine;
};

// The alignment of view j into view i's frame (X_i⁻¹ ∘ X_j), coarse then fine from `model`;
// `fine` is the coarse result where the fine cloud had too few upright pairs to align.
struct PairAlignment {
    PoseEdge edge;
    IcpResult fine;
    int coarse_iterations = 0;
};
PairAlignment AlignViewPair(int i, int j, const ViewClouds& view_j, const ViewTargets& target_i,
                            const std::vector<Se2>& model, const RegistrationConfig& config);

// Returns `alignment` as it reads in a table frame moved by `move` (from the frame it was made
// in): a capture aligns its views in the frame of the first pose's table top and fuses them in
// the plane refitted to every pose (view_stream.h). An in-plane motion is a turn about the frame's
// z axis; the turn of the table is about its true axis. Where the two axes differ by a tilt ε,
// the best in-plane motion turns about the point where the true axis crosses the height of the
// aligned surfaces, h ε to the side of the frame's axis, and carried over as it stands into a
// frame whose z axis is the true one, it would turn each view about the wrong centre: every view
// shifts along the same direction of the camera, each face outwards, and the box grows by about
// 2 h ε (0.3 mm per tenth of a degree at 20 cm). So the motion is moved as a rigid motion,
// move ∘ X ∘ move⁻¹, and read back in the plane at the alignment's own mean height
// (IcpResult::mean_height_m), where it held.
PairAlignment ReframedAlignment(PairAlignment alignment, const Eigen::Isometry3d& move);

// Returns the edges of the alignments that hold (enough matched points, small RMSE), in the
// order given, and their statistics in `stats` (when given).
std::vector<PoseEdge> AcceptedEdges(const std::vector<PairAlignment>& alignments,
                                    const RegistrationConfig& config, EdgeStats* stats);

// Returns the graph edges: each selected pair (ViewPairs) is aligned coarse-then-fine from the
// turntable model's relative pose; failed alignments are left out. Deterministic for any
// thread count.
std::vector<PoseEdge> RegisterViewPairs(const std::vector<ViewClouds>& views,
                                        const std::vector<double>& table_angles_rad,
                                        const RegistrationConfig& config, EdgeStats* stats);

}  // namespace boxd
