// AddUnseenFeet: the feet of a cuboid's side faces that nothing read (cuboid_foot.h).
#include "pipeline/envelope/cuboid_foot.h"

#include <spdlog/spdlog.h>

#include <array>
#include <cmath>
#include <vector>

#include "pipeline/core/median.h"
#include "pipeline/core/student_t.h"
#include "pipeline/envelope/foot_free_space.h"
#include "pipeline/envelope/support_envelope.h"

namespace boxd::envelope {

namespace {

// The rows of cells above the foot's that say how densely a face is read.
constexpr int kProfileRows = 4;
// A row holding less than this share of what those hold at their median was not read.
constexpr double kReadShare = 0.25;
// The readings within this of a face's reach along its normal are its own (a tapered foot stands
// out of the face's plane by its taper).
constexpr double kSlabM = 0.02;

// One side face: its outward normal, its direction across, its half width and where it stands.
struct Side {
    Eigen::Vector2d normal, across;
    double half_across = 0.0, reach = 0.0;
};

// The four side faces of the cuboid of sides `lu` along fit.length_axis and `lv` across it,
// centred at `o`: +length axis, its opposite, the axis square to it, its opposite.
std::array<Side, 4> SidesOf(const BoxFit& fit, double lu, double lv, const Eigen::Vector2d& o) {
    const Eigen::Vector2d a = fit.length_axis, b(-a.y(), a.x());
    return {Side{a, b, lv / 2.0, a.dot(o) + lu / 2.0}, Side{-a, b, lv / 2.0, -a.dot(o) + lu / 2.0},
            Side{b, a, lu / 2.0, b.dot(o) + lv / 2.0}, Side{-b, a, lu / 2.0, -b.dot(o) + lv / 2.0}};
}

// Returns whether nothing read the lowest row of cells of `side` (from the band up) while its
// rows above were read; false where the face is too low to tell.
bool FootUnread(const std::vector<Eigen::Vector3f>& pts, const Side& side,
                const Eigen::Vector2d& center, double height, const EnvelopeConfig& config) {
    std::array<int, kProfileRows + 1> rows{};
    for (const Eigen::Vector3f& p : pts) {
        const Eigen::Vector2d q = p.head<2>().cast<double>();
        if (std::abs(side.normal.dot(q) - side.reach) > kSlabM) continue;
        if (std::abs(side.across.dot(q - center)) > side.half_across) continue;
        const double row = std::floor((p.z() - config.min_z_m) / config.cell_height_m);
        if (row >= 0.0 && row <= kProfileRows) ++rows[static_cast<std::size_t>(row)];
    }
    std::vector<double> above;
    for (int k = 1; k <= kProfileRows; ++k) {
        if (config.min_z_m + (k + 1) * config.cell_height_m > height) break;
        above.push_back(rows[static_cast<std::size_t>(k)]);
    }
    if (above.empty()) return false;
    const double typical = Median(above);
    return typical >= config.min_cell_points && rows[0] < kReadShare * typical;
}

}  // namespace

Status AddUnseenFeet(const Surface& surface, const BoxFit& fit, double lu, double lv, double sigma,
                     const EnvelopeConfig& config, EnclosingCuboid* c) {
    if (!surface.table_known) return OkStatus();
    const Eigen::Vector2d o = c->center_m;
    const std::array<Side, 4> sides = SidesOf(fit, lu, lv, o);
    const TableBeside table = TableBesideOf(surface, sigma, config);
    std::array<double, 4> se{};
    for (std::size_t f = 0; f < 4; ++f) {
        if (!FootUnread(surface.points, sides[f], o, c->height_m, config)) continue;
        const double free = FreeReach(table, surface.points, sides[f].normal);
        if (!std::isfinite(free)) return FootUnreadRefusal();
        se[f] = std::max(0.0, free - sides[f].reach) / kNormal95;
    }
    const double extra_u = std::hypot(se[0], se[1]), extra_v = std::hypot(se[2], se[3]);
    c->sigma_m[0] = std::hypot(c->sigma_m[0], lu >= lv ? extra_u : extra_v);
    c->sigma_m[1] = std::hypot(c->sigma_m[1], lu >= lv ? extra_v : extra_u);
    return OkStatus();
}

int SideLeaningOut(const Surface& surface, const BoxFit& fit, double lu, double lv,
                   const Eigen::Vector2d& center, const std::array<double, 4>& face_se,
                   double sigma, const EnvelopeConfig& config) {
    const std::array<Side, 4> sides = SidesOf(fit, lu, lv, center);
    for (std::size_t f = 0; f < 4; ++f) {
        const FootReach foot = FootAlong(surface, sides[f].normal, sigma, config);
        if (!std::isfinite(foot.reach)) continue;
        const double beyond = foot.reach - sides[f].reach, se = std::hypot(foot.se, face_se[f]);
        spdlog::debug("envelope: side {} foot {:+.2f} mm beyond its face (se {:.2f}, slope {:.3f})",
                      f, beyond * 1e3, se * 1e3, foot.slope);
        if (beyond > kNormal95 * se) return static_cast<int>(f);
    }
    return -1;
}

}  // namespace boxd::envelope
