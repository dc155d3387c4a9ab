#include "pipeline/envelope/foot_free_space.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <vector>

#include "pipeline/core/student_t.h"

namespace boxd::envelope {

namespace {

// The table readings a strip needs beyond the object: the nearest two may be strays (a mixed
// pixel at the silhouette, a reading landed far inside by its noise).
constexpr int kNearest = 3;

// One strip across the direction: the object's outermost reading in it and the nearest table
// readings beyond that.
struct Strip {
    double object = -INFINITY;
    std::array<double, kNearest> table{INFINITY, INFINITY, INFINITY};

    void AddTable(double s) {
        if (s >= table.back()) return;
        table.back() = s;
        std::sort(table.begin(), table.end());
    }
};

}  // namespace

double TableReadingSpread(double sigma_m, const std::vector<Eigen::Vector3f>& cameras) {
    double lowest = INFINITY;  // the smallest tan(elevation) of a ray from a camera to the axis
    for (const Eigen::Vector3f& c : cameras) {
        const double across = c.head<2>().cast<double>().norm();
        if (across > 0.0) lowest = std::min(lowest, static_cast<double>(c.z()) / across);
    }
    // A camera looking along the table top sees its readings' noise all along it.
    if (!std::isfinite(lowest) || lowest < 0.05) return sigma_m / 0.05;
    return sigma_m / lowest;
}

double FreeReach(const TableBeside& table, const std::vector<Eigen::Vector3f>& object,
                 const Eigen::Vector2d& u) {
    if (table.points == nullptr || object.empty()) return INFINITY;
    const Eigen::Vector2f uf = u.cast<float>(), vf(-uf.y(), uf.x());
    const double inv = 1.0 / table.strip_m;
    const long half = static_cast<long>(std::ceil(table.radius_m * inv)) + 1;
    std::vector<Strip> strips(static_cast<std::size_t>(2 * half + 1));
    auto strip = [&](const Eigen::Vector2f& q) -> Strip* {
        const long k = static_cast<long>(std::floor(vf.dot(q) * inv)) + half;
        if (k < 0 || k >= static_cast<long>(strips.size())) return nullptr;
        return &strips[static_cast<std::size_t>(k)];
    };
    for (const Eigen::Vector3f& p : object) {
        if (Strip* s = strip(p.head<2>())) {
            s->object = std::max(s->object, static_cast<double>(uf.dot(p.head<2>())));
        }
    }
    for (const Eigen::Vector2f& q : *table.points) {
        Strip* s = strip(q);
        if (s == nullptr || !std::isfinite(s->object)) continue;
        const double along = uf.dot(q);
        if (along > s->object - table.tolerance_m) s->AddTable(along);
    }
    double reach = -INFINITY;
    for (const Strip& s : strips) {
        if (std::isfinite(s.object)) reach = std::max(reach, s.table.back());
    }
    return reach + table.tolerance_m;
}

void ReachBelow(const FootReach& foot, const std::vector<Eigen::Vector3f>& pts,
                const Eigen::Vector2d& u, const TableBeside* table, SideReach& side) {
    if (!foot.raised) {
        if (foot.reach > side.reach) {
            side.reach = foot.reach;
            side.se = foot.se;
        }
        // Sparse readings below the lowest judged row do not say where the wall ends: the
        // bound reaches the free table beyond.
        const double free =
            foot.above_band && table != nullptr ? FreeReach(*table, pts, u) : -INFINITY;
        if (std::isfinite(free) && free > side.reach) side.unseen = (free - side.reach) / kNormal95;
        return;
    }
    if (table == nullptr) return;
    const double free = FreeReach(*table, pts, u);
    if (!std::isfinite(free)) {
        side.open = true;
        return;
    }
    // The readings hold the reach from below and the table from above; within that, a wall
    // sloping outward goes on sloping. The bound reaches the table's limit, and below as far as
    // the extrapolation's own error or the readings, whichever is nearer. Where the table was
    // read where the wall would have gone on to, it did not: it turned in somewhere between its
    // lowest readings and the table (a sack's bulge over a narrower foot), and where is unseen.
    const double read = side.reach;
    if (free <= read) return;
    side.reach = std::clamp(foot.reach, read, free);
    if (foot.reach > free) {
        side.unseen = (free - read) / kNormal95;
        return;
    }
    side.se = std::max(side.se, std::min(side.reach - read, kNormal95 * foot.se) / kNormal95);
    side.unseen = (free - side.reach) / kNormal95;
}

TableBeside TableBesideOf(const Surface& surface, double sigma, const EnvelopeConfig& config) {
    // A table reading may land this many of its spreads inside the table's true edge by its
    // noise (TableReadingSpread), so the free space beside a foot begins that much farther out:
    // three of the few readings at the edge (FreeReach reads a strip's third nearest) all
    // landing 1.5 spreads inside it is a chance of a few in a thousand.
    constexpr double kTableSpreadSigmas = 1.5;
    return TableBeside{surface.table_known ? &surface.table : nullptr,
                       kTableSpreadSigmas * TableReadingSpread(sigma, surface.cameras),
                       config.cell_along_m / 4.0, surface.radius};
}

Error FootUnreadRefusal() {
    return Error{ErrorCode::kInsufficientData,
                 "nothing was read at the foot of a side of the object, nor on the table beside "
                 "it: how far it reaches there is unknown (a dark or glossy base, or a shadow; a "
                 "matte label round the base, a lighter table top or a second camera angle "
                 "helps)"};
}

}  // namespace boxd::envelope
