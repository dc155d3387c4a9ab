#include "pipeline/fit/fusion.h"

#include <algorithm>
#include <cmath>

#include "pipeline/core/key_index.h"

namespace boxd {

Status FusionConfig::Validate() const {
    auto bad = [](const std::string& f, const std::string& why) -> Status {
        return Error{ErrorCode::kInvalidConfig, "fusion." + f + ": " + why};
    };
    if (!(support_voxel_m > 0.0005 && support_voxel_m < 0.1)) {
        return bad("support_voxel_m", "must be in (0.0005, 0.1)");
    }
    if (min_support_points < 1) return bad("min_support_points", "must be >= 1");
    if (!(surface_tolerance_m > 0.0)) return bad("surface_tolerance_m", "must be > 0");
    if (!(min_view_inlier_fraction >= 0.0 && min_view_inlier_fraction <= 1.0)) {
        return bad("min_view_inlier_fraction", "must be in [0, 1]");
    }
    if (min_view_points < 1) return bad("min_view_points", "must be >= 1");
    return OkStatus();
}

FusedCloud FuseViews(const std::vector<Points>& views, const std::vector<Se2>& poses,
                     const FusionConfig& config, const std::optional<Eigen::Vector3f>& camera,
                     const std::vector<std::vector<float>>* raised) {
    FusedCloud all;
    std::size_t total = 0;
    for (const Points& v : views) total += v.size();
    all.points.reserve(total);
    all.view.reserve(total);
    // Every view's raise, where every view has one for each of its points.
    const bool with_raise = raised && raised->size() == views.size() &&
                            std::equal(views.begin(), views.end(), raised->begin(),
                                       [](const Points& v, const std::vector<float>& r) {
                                           return v.size() == r.size();
                                       });
    for (std::size_t k = 0; k < views.size(); ++k) {
        const Se2Map move(poses[k]);
        for (const Eigen::Vector3f& p : views[k]) {
            all.points.push_back(move(p));
            all.view.push_back(static_cast<std::uint16_t>(k));
        }
        if (with_raise)
            all.raised.insert(all.raised.end(), (*raised)[k].begin(), (*raised)[k].end());
    }
    const float inv = static_cast<float>(1.0 / config.support_voxel_m);
    // Each point's voxel (a dense index) and each voxel's point count.
    std::vector<std::uint32_t> voxel(all.points.size());
    std::vector<int> counts;
    KeyIndex index;
    for (std::size_t i = 0; i < all.points.size(); ++i) {
        const std::size_t v = index.Find(VoxelKey(all.points[i], inv));
        if (v == counts.size()) counts.push_back(0);
        ++counts[v];
        voxel[i] = static_cast<std::uint32_t>(v);
    }
    // With fewer than four views most of the surface is seen by a single view, at the fusion
    // stride about one point per support voxel: the support test would remove the object itself.
    // Outliers of such sessions are left to the first stage's flying-pixel removal.
    const int required = views.size() >= 4 ? config.min_support_points : 1;
    FusedCloud out;
    out.points.reserve(all.points.size());
    out.view.reserve(all.points.size());
    for (std::size_t i = 0; i < all.points.size(); ++i) {
        if (counts[voxel[i]] < required) continue;
        out.points.push_back(all.points[i]);
        out.view.push_back(all.view[i]);
        if (with_raise) out.raised.push_back(all.raised[i]);
    }
    out.unfiltered = std::move(all.points);
    out.unfiltered_view = std::move(all.view);
    if (camera) {
        for (std::size_t k = 0; k < views.size(); ++k) {
            out.cameras.push_back(Se2Map(poses[k])(*camera));
        }
    }
    return out;
}

Points FuseTableReadings(const std::vector<Points>& table, const std::vector<Se2>& poses) {
    Points out;
    for (std::size_t k = 0; k < table.size() && k < poses.size(); ++k) {
        const Se2Map move(poses[k]);
        for (const Eigen::Vector3f& p : table[k]) out.push_back(move(p));
    }
    return out;
}

ConsistencyReport CheckViewConsistency(const FusedCloud& cloud, int num_views, const BoxFit& box,
                                       const FusionConfig& config) {
    ConsistencyReport report;
    std::vector<int> total(static_cast<std::size_t>(num_views), 0);
    std::vector<int> inliers(static_cast<std::size_t>(num_views), 0);
    for (std::size_t i = 0; i < cloud.points.size(); ++i) {
        const std::size_t v = cloud.view[i];
        if (v >= total.size()) continue;
        ++total[v];
        if (DistanceToBoxSurface(box, cloud.points[i]) <= config.surface_tolerance_m) ++inliers[v];
    }
    for (int v = 0; v < num_views; ++v) {
        const auto k = static_cast<std::size_t>(v);
        if (total[k] < config.min_view_points) continue;
        ++report.judged_views;
        const double f = static_cast<double>(inliers[k]) / total[k];
        if (f < report.worst_inlier_fraction) {
            report.worst_inlier_fraction = f;
            report.worst_view = v;
        }
        if (f < config.min_view_inlier_fraction) report.inconsistent_views.push_back(v);
    }
    return report;
}

}  // namespace boxd
