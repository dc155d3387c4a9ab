#include "pipeline/registration/view_registration.h"

#include <spdlog/spdlog.h>

#include <algorithm>
#include <cmath>
#include <memory>
#include <utility>

#include "pipeline/core/parallel_for.h"

namespace boxd {

Status RegistrationConfig::Validate() const {
    if (Status s = coarse_cloud.Validate("registration.coarse_cloud"); !s) return s;
    if (Status s = fine_cloud.Validate("registration.fine_cloud"); !s) return s;
    if (Status s = coarse.Validate("registration.coarse"); !s) return s;
    if (Status s = fine.Validate("registration.fine"); !s) return s;
    auto bad = [](const std::string& f, const std::string& why) -> Status {
        return Error{ErrorCode::kInvalidConfig, "registration." + f + ": " + why};
    };
    if (max_pose_step < 1) return bad("max_pose_step", "must be >= 1");
    if (!(max_pair_angle_deg > 0.0 && max_pair_angle_deg <= 180.0)) {
        return bad("max_pair_angle_deg", "must be in (0, 180]");
    }
    if (!(min_fitness >= 0.0 && min_fitness <= 1.0)) return bad("min_fitness", "in [0, 1]");
    if (!(max_rmse_m > 0.0)) return bad("max_rmse_m", "must be > 0");
    if (threads < 1 || threads > 64) return bad("threads", "must be in 1..64");
    return OkStatus();
}

std::vector<Se2> TurntablePoses(const std::vector<double>& table_angles_rad) {
    std::vector<Se2> poses;
    for (double a : table_angles_rad) {
        poses.push_back(Se2{0.0, 0.0, Se2::WrapAngle(-(a - table_angles_rad.front()))});
    }
    return poses;
}

TurnOrder::TurnOrder(const std::vector<double>& table_angles_rad) {
    const std::size_t n = table_angles_rad.size();
    std::vector<double> wrapped(n);
    for (std::size_t k = 0; k < n; ++k) {
        const double a = std::fmod(table_angles_rad[k], 2.0 * M_PI);
        wrapped[k] = a < 0.0 ? a + 2.0 * M_PI : a;
    }
    at_.resize(n);
    for (std::size_t k = 0; k < n; ++k) at_[k] = static_cast<int>(k);
    std::stable_sort(at_.begin(), at_.end(), [&](int a, int b) {
        return wrapped[static_cast<std::size_t>(a)] < wrapped[static_cast<std::size_t>(b)];
    });
    rank_.resize(n);
    for (std::size_t r = 0; r < n; ++r)
        rank_[static_cast<std::size_t>(at_[r])] = static_cast<int>(r);
}

int TurnOrder::Neighbour(int pose, int steps) const {
    const int n = size();
    const int r = ((RankOf(pose) + steps) % n + n) % n;
    return at_[static_cast<std::size_t>(r)];
}

std::vector<int> PairedEarlierViews(int j, const TurnOrder& order,
                                    const std::vector<double>& plan_rad,
                                    const RegistrationConfig& config) {
    // The candidates are the few views within max_pose_step places on either side, whatever
    // the count.
    std::vector<int> out;
    const int n = order.size();
    const int reach = std::min(config.max_pose_step, n - 1);
    const auto uj = static_cast<std::size_t>(j);
    for (int d = 1; d <= reach; ++d) {
        for (int side : {1, -1}) {
            const int i = order.Neighbour(j, side * d);
            if (i >= j || std::find(out.begin(), out.end(), i) != out.end()) continue;
            const double diff =
                std::abs(Se2::WrapAngle(plan_rad[static_cast<std::size_t>(i)] - plan_rad[uj]));
            if (diff * 180.0 / M_PI <= config.max_pair_angle_deg) out.push_back(i);
        }
    }
    std::sort(out.begin(), out.end());
    return out;
}

void MarkLoopClosures(std::vector<PoseEdge>& edges, const std::vector<double>& table_angles_rad) {
    const TurnOrder order(table_angles_rad);
    const int n = order.size();
    // Pose 0's neighbour captured later closes the loop; two poses have one pair, no loop.
    const int closing = n >= 3 ? std::max(order.Neighbour(0, 1), order.Neighbour(0, -1)) : -1;
    for (PoseEdge& e : edges) {
        if (e.from >= n || e.to >= n) continue;
        const int d = std::abs(order.RankOf(e.from) - order.RankOf(e.to));
        const bool neighbours = std::min(d, n - d) == 1;
        const bool closes = std::min(e.from, e.to) == 0 && std::max(e.from, e.to) == closing;
        e.loop_closure = !neighbours || closes;
    }
}

std::vector<std::pair<int, int>> ViewPairs(const std::vector<double>& table_angles_rad,
                                           const RegistrationConfig& config) {
    const int n = static_cast<int>(table_angles_rad.size());
    const TurnOrder order(table_angles_rad);
    std::vector<std::pair<int, int>> pairs;
    for (int j = 1; j < n; ++j) {
        for (int i : PairedEarlierViews(j, order, table_angles_rad, config))
            pairs.emplace_back(i, j);
    }
    std::sort(pairs.begin(), pairs.end());
    return pairs;
}

ViewTargets::ViewTargets(const ViewClouds& clouds, const RegistrationConfig& config)
    : coarse(clouds.coarse, config.coarse.max_correspondence_m),
      fine(clouds.fine, config.fine.max_correspondence_m) {}

PairAlignment AlignViewPair(int i, int j, const ViewClouds& view_j, const ViewTargets& target_i,
                            const std::vector<Se2>& model, const RegistrationConfig& config) {
    const auto ui = static_cast<std::size_t>(i), uj = static_cast<std::size_t>(j);
    const Se2 init = model[ui].Inverse().Compose(model[uj]);
    const IcpResult coarse = AlignIcp(view_j.coarse, target_i.coarse, init, config.coarse);
    PairAlignment out;
    out.fine = AlignIcp(view_j.fine, target_i.fine, coarse.transform, config.fine);
    out.coarse_iterations = coarse.iterations;
    // Too few upright pairs on the fine cloud to move it (a small object in one noisy frame:
    // its 6 mm cells' normals scatter past the pairing's agreement): the coarse cloud, on cells
    // twice as large, is the measurement, and the edge carries its weaker information. Its
    // alignment is carried on by the planes alone, as the fine stage's is: the coarse stage's
    // point-to-point pull holds what the planes fix only weakly where it started, at the
    // turntable model, whose centre is the calibration's (view_registration.h).
    if (out.fine.solved < config.fine.min_correspondences &&
        coarse.solved >= config.coarse.min_correspondences) {
        IcpConfig planes = config.coarse;
        planes.point_to_point_weight = 0.0;
        out.fine = AlignIcp(view_j.coarse, target_i.coarse, coarse.transform, planes);
    }
    PoseEdge& edge = out.edge;
    edge.from = i;
    edge.to = j;
    edge.measured = out.fine.transform;
    edge.information = out.fine.information;
    edge.point_scatter = out.fine.point_scatter;
    edge.random_displacement_m = out.fine.random_displacement_m;
    edge.slide = out.fine.slide;
    return out;
}

PairAlignment ReframedAlignment(PairAlignment alignment, const Eigen::Isometry3d& move) {
    const Se2& x = alignment.edge.measured;
    Eigen::Isometry3d motion = Eigen::Isometry3d::Identity();
    motion.linear() = Eigen::AngleAxisd(x.yaw, Eigen::Vector3d::UnitZ()).toRotationMatrix();
    motion.translation() = Eigen::Vector3d(x.x, x.y, 0.0);
    const Eigen::Isometry3d moved = move * motion * move.inverse();
    // The in-plane motion that agrees with `moved` at the alignment's height: a point on the
    // axis there goes where `moved` takes it.
    const Eigen::Vector3d on_axis = moved * Eigen::Vector3d(0.0, 0.0, alignment.fine.mean_height_m);
    const Se2 reframed{on_axis.x(), on_axis.y(),
                       std::atan2(moved.linear()(1, 0), moved.linear()(0, 0))};
    alignment.edge.measured = reframed;
    alignment.fine.transform = reframed;
    return alignment;
}

std::vector<PoseEdge> AcceptedEdges(const std::vector<PairAlignment>& alignments,
                                    const RegistrationConfig& config, EdgeStats* stats) {
    std::vector<PoseEdge> accepted;
    EdgeStats st;
    double rmse_sum = 0.0;
    for (const PairAlignment& a : alignments) {
        ++st.attempted;
        const IcpResult& r = a.fine;
        spdlog::debug(
            "registration: {}-{}: {}+{} iterations, fitness {:.2f} ({} upright of {}), "
            "rmse {:.2f} mm, motion ({:.1f}, {:.1f}) mm {:.2f} deg",
            a.edge.from, a.edge.to, a.coarse_iterations, r.iterations, r.fitness, r.solved,
            r.correspondences, r.rmse * 1000.0, r.transform.x * 1000.0, r.transform.y * 1000.0,
            r.transform.yaw * 180.0 / M_PI);
        // An alignment with too few upright correspondences never left its start: its
        // "measurement" would only repeat the turntable model, as if confirming it. Where the
        // rest (the top) matched, its views share no side; where nothing did, they disagree.
        const bool matched = r.fitness >= config.min_fitness && r.rmse <= config.max_rmse_m;
        const bool sides = r.solved >= config.fine.min_correspondences;
        if (sides || !matched) {
            st.tested_views.push_back(a.edge.from);
            st.tested_views.push_back(a.edge.to);
        }
        if (!sides || !matched) continue;
        ++st.accepted;
        rmse_sum += r.rmse;
        accepted.push_back(a.edge);
    }
    st.mean_rmse_m = st.accepted > 0 ? rmse_sum / st.accepted : 0.0;
    std::sort(st.tested_views.begin(), st.tested_views.end());
    st.tested_views.erase(std::unique(st.tested_views.begin(), st.tested_views.end()),
                          st.tested_views.end());
    if (stats) *stats = st;
    return accepted;
}

std::vector<PoseEdge> RegisterViewPairs(const std::vector<ViewClouds>& views,
                                        const std::vector<double>& table_angles_rad,
                                        const RegistrationConfig& config, EdgeStats* stats) {
    const int n = static_cast<int>(views.size());
    const std::vector<Se2> model = TurntablePoses(table_angles_rad);
    const std::vector<std::pair<int, int>> list = ViewPairs(table_angles_rad, config);
    std::vector<std::unique_ptr<ViewTargets>> targets(static_cast<std::size_t>(n));
    ParallelFor(n, config.threads, [&](int k) {
        targets[static_cast<std::size_t>(k)] =
            std::make_unique<ViewTargets>(views[static_cast<std::size_t>(k)], config);
    });
    std::vector<PairAlignment> alignments(list.size());
    ParallelFor(static_cast<int>(list.size()), config.threads, [&](int e) {
        const auto [i, j] = list[static_cast<std::size_t>(e)];
        alignments[static_cast<std::size_t>(e)] =
            AlignViewPair(i, j, views[static_cast<std::size_t>(j)],
                          *targets[static_cast<std::size_t>(i)], model, config);
    });
    std::vector<PoseEdge> edges = AcceptedEdges(alignments, config, stats);
    MarkLoopClosures(edges, table_angles_rad);
    return edges;
}

}  // namespace boxd
