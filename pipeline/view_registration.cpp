#include "pipeline/view_registration.h"

#include <spdlog/spdlog.h>

#include <cmath>
#include <set>
#include <utility>

#include "pipeline/parallel_for.h"

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

std::vector<PoseEdge> RegisterViewPairs(const std::vector<ViewClouds>& views,
                                        const std::vector<double>& table_angles_rad,
                                        const RegistrationConfig& config, EdgeStats* stats) {
    const int n = static_cast<int>(views.size());
    const std::vector<Se2> model = TurntablePoses(table_angles_rad);
    // Pairs (i, j), i < j in cyclic index distance <= max_pose_step, within the angle limit.
    std::set<std::pair<int, int>> pairs;
    for (int i = 0; i < n; ++i) {
        for (int step = 1; step <= config.max_pose_step && step < n; ++step) {
            const int j = (i + step) % n;
            const double diff = std::abs(Se2::WrapAngle(model[static_cast<std::size_t>(i)].yaw -
                                                        model[static_cast<std::size_t>(j)].yaw));
            if (diff * 180.0 / M_PI > config.max_pair_angle_deg) continue;
            pairs.insert({std::min(i, j), std::max(i, j)});
        }
    }
    const std::vector<std::pair<int, int>> list(pairs.begin(), pairs.end());
    // Targets with their search indices are built once per view.
    std::vector<std::unique_ptr<IcpTarget>> coarse_targets(static_cast<std::size_t>(n));
    std::vector<std::unique_ptr<IcpTarget>> fine_targets(static_cast<std::size_t>(n));
    ParallelFor(n, config.threads, [&](int k) {
        const auto i = static_cast<std::size_t>(k);
        coarse_targets[i] =
            std::make_unique<IcpTarget>(views[i].coarse, config.coarse.max_correspondence_m);
        fine_targets[i] =
            std::make_unique<IcpTarget>(views[i].fine, config.fine.max_correspondence_m);
    });
    std::vector<PoseEdge> edges(list.size());
    std::vector<IcpResult> results(list.size());
    std::vector<int> coarse_iterations(list.size());
    ParallelFor(static_cast<int>(list.size()), config.threads, [&](int e) {
        const auto [i, j] = list[static_cast<std::size_t>(e)];
        const auto ui = static_cast<std::size_t>(i), uj = static_cast<std::size_t>(j);
        // View j into view i's frame: X_i⁻¹ ∘ X_j.
        const Se2 init = model[ui].Inverse().Compose(model[uj]);
        const IcpResult coarse =
            AlignIcp(views[uj].coarse, *coarse_targets[ui], init, config.coarse);
        const IcpResult fine =
            AlignIcp(views[uj].fine, *fine_targets[ui], coarse.transform, config.fine);
        results[static_cast<std::size_t>(e)] = fine;
        coarse_iterations[static_cast<std::size_t>(e)] = coarse.iterations;
        PoseEdge& edge = edges[static_cast<std::size_t>(e)];
        edge.from = i;
        edge.to = j;
        edge.measured = fine.transform;
        edge.information = fine.information;
        edge.point_scatter = fine.point_scatter;
        edge.loop_closure = !(j == i + 1);
    });
    std::vector<PoseEdge> accepted;
    EdgeStats st;
    double rmse_sum = 0.0;
    for (std::size_t e = 0; e < list.size(); ++e) {
        ++st.attempted;
        const IcpResult& r = results[e];
        spdlog::debug(
            "registration: {}-{}: {}+{} iterations, fitness {:.2f}, rmse {:.2f} mm, "
            "motion ({:.1f}, {:.1f}) mm {:.2f} deg",
            list[e].first, list[e].second, coarse_iterations[e], r.iterations, r.fitness,
            r.rmse * 1000.0, r.transform.x * 1000.0, r.transform.y * 1000.0,
            r.transform.yaw * 180.0 / M_PI);
        // An alignment with too few upright correspondences never left its start: its
        // "measurement" would only repeat the turntable model, as if confirming it.
        if (r.solved < config.fine.min_correspondences || r.fitness < config.min_fitness ||
            r.rmse > config.max_rmse_m) {
            continue;
        }
        ++st.accepted;
        rmse_sum += r.rmse;
        accepted.push_back(edges[e]);
    }
    st.mean_rmse_m = st.accepted > 0 ? rmse_sum / st.accepted : 0.0;
    if (stats) *stats = st;
    return accepted;
}

}  // namespace boxd
