#include "pipeline/view_stream.h"

#include <spdlog/spdlog.h>

#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>
#include <memory>

#include "pipeline/core/parallel_for.h"

namespace boxd {

namespace {

// Table candidates kept per pose: thousands are plenty for a plane, and the refit over all poses
// stays within a fixed total, so that a 360-pose session neither holds nor refits every pose's
// tens of thousands.
constexpr std::size_t kCandidatesPerPose = 4000;
constexpr std::size_t kCandidatesInAll = 100000;

std::vector<Eigen::Vector3d> EvenSubsample(std::vector<Eigen::Vector3d> pts, std::size_t most) {
    if (pts.size() <= most) return pts;
    const std::size_t step = (pts.size() + most - 1) / most;
    std::vector<Eigen::Vector3d> out;
    for (std::size_t i = 0; i < pts.size(); i += step) out.push_back(pts[i]);
    return out;
}

}  // namespace

ViewStream::ViewStream(const Session& header, std::vector<double> plan_deg, MeasureConfig config,
                       MonotonicMs clock)
    : config_(std::move(config)),
      plan_deg_(std::move(plan_deg)),
      plan_rad_(TurntableAnglesRad(plan_deg_, header.direction)),
      order_(plan_rad_),
      clock_(std::move(clock)) {
    header_.camera = header.camera;
    header_.calibration = header.calibration;
    header_.direction = header.direction;
    const auto n = plan_deg_.size();
    views_.views.resize(n);
    views_.clouds.resize(n);
    targets_.resize(n);
    candidates_.resize(n);
    PlanPairs();
}

void ViewStream::PlanPairs() {
    last_partner_.assign(plan_deg_.size(), -1);
    for (int j = 1; j < Planned(); ++j) {
        for (int i : PairedEarlierViews(j, order_, plan_rad_, config_.registration)) {
            last_partner_[static_cast<std::size_t>(i)] = j;
        }
    }
}

bool ViewStream::Follows(const Session& session) const {
    if (static_cast<int>(session.poses.size()) != Planned()) return false;
    if (session.direction != header_.direction) return false;
    for (std::size_t i = 0; i < plan_deg_.size(); ++i) {
        if (session.poses[i].angle_deg != plan_deg_[i]) return false;
    }
    return true;
}

bool ViewStream::Matches(const Session& session) const {
    return Added() == Planned() && Follows(session);
}

void ViewStream::Truncate(int poses) {
    const auto n = static_cast<std::size_t>(std::clamp(poses, Added(), Planned()));
    plan_deg_.resize(n);
    plan_rad_.resize(n);
    order_ = TurnOrder(plan_rad_);
    views_.views.resize(n);
    views_.clouds.resize(n);
    targets_.resize(n);
    candidates_.resize(n);
    PlanPairs();
}

std::unique_ptr<ViewStream> ViewStream::SoFar() const {
    if (!pending_.empty()) return nullptr;
    const auto n = static_cast<std::size_t>(Added());
    std::vector<double> plan(plan_deg_.begin(), plan_deg_.begin() + static_cast<long>(n));
    auto copy = std::make_unique<ViewStream>(header_, std::move(plan), config_, clock_);
    copy->added_ = added_;
    copy->unusable_ = unusable_;
    copy->table_error_ = table_error_;
    std::copy(candidates_.begin(), candidates_.begin() + static_cast<long>(n),
              copy->candidates_.begin());
    copy->provisional_ = provisional_;
    copy->segmented_ = segmented_;
    std::copy(views_.views.begin(), views_.views.begin() + static_cast<long>(n),
              copy->views_.views.begin());
    std::copy(views_.clouds.begin(), views_.clouds.begin() + static_cast<long>(n),
              copy->views_.clouds.begin());
    copy->alignments_ = alignments_;
    copy->multipath_ = multipath_;
    copy->segment_ms_ = segment_ms_;  // the copy's laps are those of its poses
    copy->align_ms_ = align_ms_;
    return copy;
}

ViewStream::Inspected ViewStream::Inspect(std::size_t k, PreparedPose pose) const {
    Inspected out;
    out.depth = UsableDepth(std::move(pose), k, config_.refusal);
    if (!out.depth) return out;
    MultipathCorrection corrected =
        CorrectMultipath(std::move(*out.depth), header_.camera, header_.calibration);
    out.depth = std::move(corrected.depth);
    out.multipath = corrected.share;
    const std::size_t share = std::max<std::size_t>(
        100, std::min(kCandidatesPerPose,
                      kCandidatesInAll / std::max<std::size_t>(1, plan_deg_.size())));
    out.candidates = EvenSubsample(
        TableCandidates(*out.depth, header_.camera, header_.calibration, config_.table_plane),
        share);
    return out;
}

bool ViewStream::Accept(std::size_t k, Inspected pose) {
    if (!pose.depth) {
        unusable_ = pose.depth.error();
        return false;
    }
    candidates_[k] = std::move(pose.candidates);
    multipath_.Widen(pose.multipath);
    pending_.push_back(std::move(*pose.depth));
    return true;
}

void ViewStream::TryTable() {
    if (provisional_) return;
    auto fit = FitTableCandidates(candidates_, header_.calibration, config_.table_plane);
    if (fit) {
        provisional_ = *fit;
        table_error_.reset();
    } else {
        table_error_ = fit.error();
    }
}

void ViewStream::SegmentInto(std::size_t k, const DepthMap& depth) {
    SegmentObjectView(depth, header_.camera, header_.calibration, provisional_->camera_to_table,
                      config_.segmentation, config_.registration.coarse_cloud,
                      config_.registration.fine_cloud, Planned() == 1, static_cast<int>(k),
                      &views_.views[k], &views_.clouds[k]);
    targets_[k] = std::make_unique<ViewTargets>(views_.clouds[k], config_.registration);
}

void ViewStream::Add(PreparedPose pose) {
    std::vector<PreparedPose> one;
    one.push_back(std::move(pose));
    AddAll(std::move(one));
}

void ViewStream::AddAll(std::vector<PreparedPose> poses) {
    const double t0 = Now();
    const int first = Added();
    const int n = std::min(Planned() - first, static_cast<int>(poses.size()));
    if (n <= 0) return;
    added_ += n;
    // Each pose in order: checked, its table candidates, and the provisional table once they
    // locate it — the same sequence whether the poses come one by one or all at once.
    std::vector<Inspected> inspected(static_cast<std::size_t>(n));
    ParallelFor(n, config_.threads, [&](int i) {
        const auto k = static_cast<std::size_t>(i);
        inspected[k] = Inspect(static_cast<std::size_t>(first + i), std::move(poses[k]));
    });
    for (int i = 0; i < n && !Blocked(); ++i) {
        if (!Accept(static_cast<std::size_t>(first + i),
                    std::move(inspected[static_cast<std::size_t>(i)]))) {
            break;
        }
        TryTable();
    }
    if (Blocked() || !provisional_) {
        segment_ms_ += (Now() - t0);
        return;
    }
    // The views waiting for the table, then their alignments with the views before them.
    const int from = segmented_;
    const int count = static_cast<int>(pending_.size());
    ParallelFor(count, config_.threads, [&](int i) {
        SegmentInto(static_cast<std::size_t>(from + i), pending_[static_cast<std::size_t>(i)]);
    });
    pending_.clear();
    segmented_ = from + count;
    segment_ms_ += (Now() - t0);
    const double t1 = Now();
    std::vector<std::pair<int, int>> pairs;
    for (int j = from; j < segmented_; ++j) {
        for (int i : PairedEarlierViews(j, order_, plan_rad_, config_.registration)) {
            pairs.emplace_back(i, j);
        }
    }
    const std::vector<Se2> model = TurntablePoses(plan_rad_);
    std::vector<PairAlignment> aligned(pairs.size());
    ParallelFor(static_cast<int>(pairs.size()), config_.threads, [&](int e) {
        const auto [i, j] = pairs[static_cast<std::size_t>(e)];
        aligned[static_cast<std::size_t>(e)] =
            AlignViewPair(i, j, views_.clouds[static_cast<std::size_t>(j)],
                          *targets_[static_cast<std::size_t>(i)], model, config_.registration);
    });
    for (PairAlignment& a : aligned) alignments_.push_back(std::move(a));
    // A view's search index is done with once the last view it is aligned with is in.
    for (int i = 0; i < segmented_; ++i) {
        if (last_partner_[static_cast<std::size_t>(i)] < segmented_) {
            targets_[static_cast<std::size_t>(i)].reset();
        }
    }
    align_ms_ += (Now() - t1);
}

std::optional<MeasurementReason> ViewStream::Complete() {
    if (Planned() == 0) {
        return MeasurementReason{ErrorCode::kInsufficientData, "the session has no poses"};
    }
    if (unusable_) return unusable_;
    if (!provisional_) {
        if (table_error_) return table_error_;
        return MeasurementReason{ErrorCode::kInsufficientData, "no pose locates the table"};
    }
    if (!completed_) {
        completed_ = true;
        // The plane of every pose's table top, and the views moved from the provisional frame
        // into it.
        auto all = FitTableCandidates(candidates_, header_.calibration, config_.table_plane);
        if (!all) {
            table_error_ = all.error();
        } else {
            table_ = *all;
            move_ = table_.camera_to_table * provisional_->camera_to_table.inverse();
            const Eigen::Isometry3f move = move_.cast<float>();
            spdlog::debug(
                "table: refitted to every pose, the views move by {:.3f} mm and {:.4f} deg",
                move.translation().norm() * 1e3,
                Eigen::AngleAxisf(move.linear()).angle() * 180.0 / M_PI);
            for (SegmentedView& v : views_.views) {
                for (Eigen::Vector3f& p : v.fusion_points) p = move * p;
                for (Eigen::Vector3f& p : v.points) p = move * p;
                for (Eigen::Vector3f& p : v.table_points) p = move * p;
            }
            table_error_.reset();
        }
        candidates_.clear();
        views_.fusion_points = 0;
        for (const SegmentedView& v : views_.views) {
            views_.fusion_points += static_cast<long>(v.fusion_points.size());
        }
    }
    if (table_error_) return table_error_;
    return CheckObjectViews(views_, config_.refusal);
}

std::vector<PoseEdge> ViewStream::Edges(EdgeStats* stats) const {
    // The alignments were made in the provisional frame; the views are fused in the refitted one.
    std::vector<PairAlignment> sorted;
    sorted.reserve(alignments_.size());
    for (const PairAlignment& a : alignments_) sorted.push_back(ReframedAlignment(a, move_));
    std::sort(sorted.begin(), sorted.end(), [](const PairAlignment& a, const PairAlignment& b) {
        return std::pair(a.edge.from, a.edge.to) < std::pair(b.edge.from, b.edge.to);
    });
    std::vector<PoseEdge> edges = AcceptedEdges(sorted, config_.registration, stats);
    MarkLoopClosures(edges, plan_rad_);
    return edges;
}

}  // namespace boxd
