#pragma once
// The views stage and the ICP of registration pose by pose, as a capture delivers them: the table
// frame from the first pose, then each view's object points and registration clouds, and its ICP
// alignments with the views before it (its neighbours, and at the end of the turn the loop closures
// with the first ones). A capture runs them while the table turns, so that after its last pose only
// that pose's own share, the pose graph, fusion and the fits remain. MeasurePrepared feeds a whole
// session at once (views and alignments in parallel); either way the views and edges are the same.
//
// The views are cut in the table frame of the first pose's table top (every pose sees the same
// plane, the table turns in it, and one pose holds thousands of table readings), known before
// the second pose arrives; a pose whose table is hidden waits for the next ones. Once every pose
// is in, the plane is refitted to the table top of all of them, and the views' points move by
// the small correction (tenths of a millimetre) before they are fused: heights are measured
// from the plane every pose saw. The alignments move with them (Edges, ReframedAlignment).

#include <memory>
#include <optional>
#include <utility>
#include <vector>

#include "pipeline/core/stage_laps.h"
#include "pipeline/frames/multipath_correction.h"
#include "pipeline/frames/prepare_pose.h"
#include "pipeline/io/session.h"
#include "pipeline/measure_config.h"
#include "pipeline/refusal.h"
#include "pipeline/registration/view_registration.h"
#include "pipeline/views/object_views.h"
#include "pipeline/views/table_plane.h"

namespace boxd {

class ViewStream {
public:
    // `header`: the session's camera, calibration and turntable direction (its poses are not
    // read); `plan_deg`: the commanded angles of the poses the session will have, in the order
    // they come (which views are neighbours around the turn, and so are aligned, depends on all
    // of them). `clock` times the stages (their laps stay zero without one).
    ViewStream(const Session& header, std::vector<double> plan_deg, MeasureConfig config,
               MonotonicMs clock = {});

    // Adds the next pose of the plan (index Added()) and does its share of the stages. Poses
    // beyond the plan are ignored.
    void Add(PreparedPose pose);

    // Adds the poses that follow (prepared, in plan order) at once, each stage on
    // config.threads threads.
    void AddAll(std::vector<PreparedPose> poses);

    int Added() const { return added_; }
    int Planned() const { return static_cast<int>(plan_deg_.size()); }
    // Whether `session` is the planned one (its count, direction and angles), and whether every
    // one of its poses is in.
    bool Follows(const Session& session) const;
    bool Matches(const Session& session) const;
    // Ends the plan after its first `poses` poses (not fewer than Added()): a capture that
    // stopped early. The alignments made so far stay.
    void Truncate(int poses);
    // A copy of the poses added so far, as a stream whose plan ends there, for a measurement
    // of them while this one goes on (its views are copied; no alignment can be added to it).
    // Null while some pose waits for the table.
    std::unique_ptr<ViewStream> SoFar() const;

    // Once every pose is added: refits the table to all poses and moves the views into that
    // frame (once), and returns the first refusal in the stages' order (an unusable pose, then
    // the table, then the views' checks).
    std::optional<MeasurementReason> Complete();
    // After Complete: the table fit, the views, the accepted edges (in the refitted frame) with
    // their statistics.
    const TablePlaneFit& table() const { return table_; }
    // After Complete: whether the table top was found (a refusal before it is the table's).
    bool TableFound() const { return completed_ && !table_error_; }
    ObjectViews& views() { return views_; }
    std::vector<PoseEdge> Edges(EdgeStats* stats) const;
    // Time spent in Add / AddAll: the table and the views, and the alignments.
    double segment_ms() const { return segment_ms_; }
    double align_ms() const { return align_ms_; }
    // The largest of the views' median multipath corrections of their object's readings, on its
    // walls and on all of it (multipath_correction.h; 0 for a camera without multipath).
    const MultipathShare& multipath() const { return multipath_; }

private:
    // A pose looked at before it is taken: its depth (or why it is unusable) and its table
    // candidates. Poses are inspected on the worker threads, then taken in order.
    struct Inspected {
        Result<DepthMap> depth = DepthMap{};
        std::vector<Eigen::Vector3d> candidates;
        MultipathShare multipath;  // the median multipath corrections of the object's readings
    };
    Inspected Inspect(std::size_t k, PreparedPose pose) const;
    // Takes pose k (its depth, its table candidates); false when it is unusable.
    bool Accept(std::size_t k, Inspected pose);
    void TryTable();  // the provisional table frame from the candidates so far
    void SegmentInto(std::size_t k, const DepthMap& depth);
    bool Blocked() const { return unusable_.has_value(); }
    double Now() const { return clock_ ? clock_() : 0.0; }

    // The pose each view's search index waits for: the last planned view it is aligned with.
    void PlanPairs();

    Session header_;
    MeasureConfig config_;
    std::vector<double> plan_deg_, plan_rad_;
    TurnOrder order_;
    std::vector<int> last_partner_;
    int added_ = 0;
    std::optional<MeasurementReason> unusable_, table_error_;
    std::vector<std::vector<Eigen::Vector3d>> candidates_;  // per pose, subsampled
    std::optional<TablePlaneFit> provisional_;
    TablePlaneFit table_;
    // From the provisional table frame the alignments were made in to the refitted one.
    Eigen::Isometry3d move_ = Eigen::Isometry3d::Identity();
    std::vector<DepthMap> pending_;  // accepted depths not yet cut into views, from `segmented_`
    int segmented_ = 0;
    bool completed_ = false;
    ObjectViews views_;
    std::vector<std::unique_ptr<ViewTargets>> targets_;
    std::vector<PairAlignment> alignments_;  // in the order they were made
    MonotonicMs clock_;
    double segment_ms_ = 0.0, align_ms_ = 0.0;
    MultipathShare multipath_;
};

}  // namespace boxd
