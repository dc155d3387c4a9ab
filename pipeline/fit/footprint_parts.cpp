#include "pipeline/fit/footprint_parts.h"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <numeric>
#include <unordered_map>
#include <unordered_set>
#include <utility>

#include "pipeline/core/median.h"

namespace boxd {

namespace {

using Flat = std::vector<Eigen::Vector2f>;

std::int64_t Key(int x, int y) {
    return (static_cast<std::int64_t>(x) << 32) ^ static_cast<std::uint32_t>(y);
}

int Index(double v, double inv) { return static_cast<int>(std::floor(v * inv)); }

// The footprint without the lone readings at its edge (footprint_parts.h).
Flat WithoutStrays(const Flat& xy, double cell_m, double stray_share) {
    const double inv = 1.0 / cell_m;
    std::unordered_map<std::int64_t, int> count;
    for (const Eigen::Vector2f& p : xy) ++count[Key(Index(p.x(), inv), Index(p.y(), inv))];
    std::vector<double> counts;
    counts.reserve(count.size());
    for (const auto& [key, n] : count) counts.push_back(n);
    const double stray = stray_share * Median(std::move(counts));
    auto occupied = [&](int x, int y) { return count.count(Key(x, y)) > 0; };
    Flat kept;
    kept.reserve(xy.size());
    for (const Eigen::Vector2f& p : xy) {
        const int x = Index(p.x(), inv), y = Index(p.y(), inv);
        const bool edge = !occupied(x + 1, y) || !occupied(x - 1, y) || !occupied(x, y + 1) ||
                          !occupied(x, y - 1);
        if (!(edge && count[Key(x, y)] < stray)) kept.push_back(p);
    }
    return kept;
}

// Where the table was read and nothing of the object: cells of `cell_m` holding a table reading
// and no footprint reading. A segment crossing one crosses seen free table.
class FreeTable {
public:
    FreeTable(const Points& table, const Flat& footprint, double cell_m) : inv_(1.0 / cell_m) {
        std::unordered_set<std::int64_t> object;
        for (const Eigen::Vector2f& p : footprint) object.insert(KeyOf(p.cast<double>()));
        for (const Eigen::Vector3f& t : table) {
            const std::int64_t key = KeyOf(t.head<2>().cast<double>());
            if (!object.count(key)) free_.insert(key);
        }
        step_ = 0.5 * cell_m;
    }

    // Whether the segment from a to b crosses a free cell.
    bool Crosses(const Eigen::Vector2d& a, const Eigen::Vector2d& b) const {
        if (free_.empty()) return false;
        const double length = (b - a).norm();
        const int steps = static_cast<int>(std::ceil(length / step_));
        for (int i = 0; i <= steps; ++i) {
            const double t = steps > 0 ? static_cast<double>(i) / steps : 0.0;
            if (free_.count(KeyOf(a + t * (b - a)))) return true;
        }
        return false;
    }

private:
    std::int64_t KeyOf(const Eigen::Vector2d& p) const {
        return Key(Index(p.x(), inv_), Index(p.y(), inv_));
    }

    double inv_, step_ = 0.0;
    std::unordered_set<std::int64_t> free_;
};

// The readings sorted into square cells whose diagonal is the link (any two readings of one cell
// are linked), and the union-find over the cells.
class LinkGrid {
public:
    LinkGrid(Flat xy, double link_m) : xy_(std::move(xy)), link_m_(link_m) {
        inv_ = std::sqrt(2.0) / link_m;
        std::vector<std::pair<std::int64_t, int>> keyed(xy_.size());
        for (std::size_t i = 0; i < xy_.size(); ++i) {
            keyed[i] = {Key(Index(xy_[i].x(), inv_), Index(xy_[i].y(), inv_)), static_cast<int>(i)};
        }
        std::sort(keyed.begin(), keyed.end());
        Flat sorted(xy_.size());
        for (std::size_t i = 0; i < keyed.size(); ++i) {
            sorted[i] = xy_[static_cast<std::size_t>(keyed[i].second)];
            if (i == 0 || keyed[i].first != keyed[i - 1].first) {
                const Eigen::Vector2f& p = sorted[i];
                index_[keyed[i].first] = static_cast<int>(cells_.size());
                cells_.push_back({Index(p.x(), inv_), Index(p.y(), inv_), static_cast<int>(i), 0,
                                  Eigen::Vector2d::Zero()});
            }
            cells_.back().end = static_cast<int>(i) + 1;
            cells_.back().centroid += sorted[i].cast<double>();
        }
        for (Cell& c : cells_) c.centroid /= static_cast<double>(c.end - c.begin);
        xy_ = std::move(sorted);
        parent_.resize(cells_.size());
        std::iota(parent_.begin(), parent_.end(), 0);
    }

    // Joins every two cells holding readings within the link of each other: only cells up to
    // two apart can (their nearest corners are a diagonal, the link, apart).
    void Link() {
        ForPairs(2, [&](const Cell& a, const Cell& b) { return Near(a, b); });
    }

    // Joins every two cells whose centroids lie within `reach_m` where the straight way between
    // them crosses no table seen free.
    void Bridge(const FreeTable& free, double reach_m) {
        const int cells = static_cast<int>(std::ceil(reach_m * inv_)) + 1;
        ForPairs(cells, [&](const Cell& a, const Cell& b) {
            return (a.centroid - b.centroid).norm() <= reach_m &&
                   !free.Crosses(a.centroid, b.centroid);
        });
    }

    // The number of cells of each part.
    std::vector<int> PartCells() {
        std::unordered_map<int, int> cells;
        for (std::size_t c = 0; c < cells_.size(); ++c) ++cells[Find(static_cast<int>(c))];
        std::vector<int> out;
        for (const auto& [root, n] : cells) out.push_back(n);
        return out;
    }

private:
    struct Cell {
        int x, y, begin, end;  // its readings are xy_[begin, end)
        Eigen::Vector2d centroid;
    };

    // Joins the cells up to `reach` cells apart in either direction that are not joined yet and
    // that `join` says should be.
    template <typename Join>
    void ForPairs(int reach, Join&& join) {
        for (std::size_t c = 0; c < cells_.size(); ++c) {
            for (int dx = 0; dx <= reach; ++dx) {
                for (int dy = -reach; dy <= reach; ++dy) {
                    if (dx == 0 && dy <= 0) continue;  // each pair once
                    auto it = index_.find(Key(cells_[c].x + dx, cells_[c].y + dy));
                    if (it == index_.end()) continue;
                    const int a = Find(static_cast<int>(c)), b = Find(it->second);
                    if (a != b && join(cells_[c], cells_[static_cast<std::size_t>(it->second)])) {
                        parent_[static_cast<std::size_t>(a)] = b;
                    }
                }
            }
        }
    }

    int Find(int c) {
        while (parent_[static_cast<std::size_t>(c)] != c) {
            auto& up = parent_[static_cast<std::size_t>(c)];
            up = parent_[static_cast<std::size_t>(up)];
            c = up;
        }
        return c;
    }

    bool Near(const Cell& a, const Cell& b) const {
        const double link2 = link_m_ * link_m_;
        for (int i = a.begin; i < a.end; ++i) {
            for (int j = b.begin; j < b.end; ++j) {
                const auto& p = xy_[static_cast<std::size_t>(i)];
                const auto& q = xy_[static_cast<std::size_t>(j)];
                if ((p - q).cast<double>().squaredNorm() <= link2) return true;
            }
        }
        return false;
    }

    Flat xy_;
    double link_m_, inv_ = 1.0;
    std::vector<Cell> cells_;
    std::unordered_map<std::int64_t, int> index_;
    std::vector<int> parent_;
};

}  // namespace

FootprintParts SeparateFootprint(const Points& points, const Points& table,
                                 const FootprintLinks& links) {
    Flat xy;
    xy.reserve(points.size());
    for (const Eigen::Vector3f& p : points) {
        if (p.z() >= links.min_height_m) xy.emplace_back(p.x(), p.y());
    }
    xy = WithoutStrays(xy, links.link_m, links.stray_share);
    const FreeTable free(table, xy, 0.5 * links.link_m);
    LinkGrid grid(std::move(xy), links.link_m);
    grid.Link();
    grid.Bridge(free, links.unread_reach_m);
    const double cell_area = 0.5 * links.link_m * links.link_m;
    FootprintParts parts;
    for (int cells : grid.PartCells()) {
        parts.area_m2.push_back(cells * cell_area);
        parts.total_m2 += cells * cell_area;
    }
    return parts;
}

}  // namespace boxd
