#include "pipeline/fit/footprint_parts.h"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <numeric>
#include <unordered_map>
#include <utility>

#include "pipeline/core/median.h"

namespace boxd {

namespace {

using Flat = std::vector<Eigen::Vector2f>;

std::int64_t Key(int x, int y) {
    return (static_cast<std::int64_t>(x) << 32) ^ static_cast<std::uint32_t>(y);
}

int Index(double v, double inv) { return static_cast<int>(std::floor(v * inv)); }

// Readings closer than this across the table are one place to the links.
constexpr double kDistinctM = 0.001;

// A square grid of `cell_m` over the box [lo, hi], a T a cell.
template <typename T>
class Raster {
public:
    Raster(const std::pair<Eigen::Vector2d, Eigen::Vector2d>& box, double cell_m)
        : Raster(box.first, box.second, cell_m) {}
    Raster(const Eigen::Vector2d& lo, const Eigen::Vector2d& hi, double cell_m)
        : lo_(lo), inv_(1.0 / cell_m) {
        nx_ = static_cast<int>(std::ceil((hi.x() - lo.x()) * inv_)) + 1;
        ny_ = static_cast<int>(std::ceil((hi.y() - lo.y()) * inv_)) + 1;
        cells_.assign(static_cast<std::size_t>(nx_) * static_cast<std::size_t>(ny_), 0);
    }

    // The cell of p, or nullptr outside the box.
    T* At(const Eigen::Vector2d& p) {
        const long k = Offset(p);
        return k < 0 ? nullptr : &cells_[static_cast<std::size_t>(k)];
    }
    // The value of the cell of p, 0 outside the box.
    T Get(const Eigen::Vector2d& p) const {
        const long k = Offset(p);
        return k < 0 ? 0 : cells_[static_cast<std::size_t>(k)];
    }

private:
    long Offset(const Eigen::Vector2d& p) const {
        const int x = Index(p.x() - lo_.x(), inv_), y = Index(p.y() - lo_.y(), inv_);
        if (x < 0 || y < 0 || x >= nx_ || y >= ny_) return -1;
        return static_cast<long>(y) * nx_ + x;
    }

    Eigen::Vector2d lo_;
    double inv_;
    int nx_ = 0, ny_ = 0;
    std::vector<T> cells_;
};

// The box of `xy` grown by `margin`.
std::pair<Eigen::Vector2d, Eigen::Vector2d> Bounds(const Flat& xy, double margin) {
    Eigen::Vector2d lo = Eigen::Vector2d::Constant(INFINITY), hi = -lo;
    for (const Eigen::Vector2f& p : xy) {
        lo = lo.cwiseMin(p.cast<double>());
        hi = hi.cwiseMax(p.cast<double>());
    }
    return {lo.array() - margin, hi.array() + margin};
}

// The footprint without the lone readings at its edge (footprint_parts.h).
Flat WithoutStrays(const Flat& xy, double cell_m, double stray_share) {
    if (xy.empty()) return xy;
    const auto [lo, hi] = Bounds(xy, 2.0 * cell_m);
    Raster<int> count(lo, hi, cell_m);
    for (const Eigen::Vector2f& p : xy) ++*count.At(p.cast<double>());
    std::vector<double> counts;
    for (const Eigen::Vector2f& p : xy) {
        // Each occupied cell's count once: at its first reading, marked by the sign.
        int* c = count.At(p.cast<double>());
        if (*c > 0) {
            counts.push_back(*c);
            *c = -*c;
        }
    }
    const double stray = stray_share * Median(std::move(counts));
    auto occupied = [&](const Eigen::Vector2d& q) { return count.Get(q) != 0; };
    Flat kept;
    kept.reserve(xy.size());
    for (const Eigen::Vector2f& p : xy) {
        const Eigen::Vector2d q = p.cast<double>();
        const bool edge = !occupied(q + Eigen::Vector2d(cell_m, 0.0)) ||
                          !occupied(q - Eigen::Vector2d(cell_m, 0.0)) ||
                          !occupied(q + Eigen::Vector2d(0.0, cell_m)) ||
                          !occupied(q - Eigen::Vector2d(0.0, cell_m));
        if (!(edge && -count.Get(q) < stray)) kept.push_back(p);
    }
    return kept;
}

// One reading per `cell_m` square: the footprint of a wall holds its readings of every height at
// one place, and the links need each place once (a millimetre moves no link of a centimetre).
Flat Distinct(const Flat& xy, double cell_m) {
    if (xy.empty()) return xy;
    const auto [lo, hi] = Bounds(xy, 0.0);
    Raster<std::uint8_t> seen(lo, hi, cell_m);
    Flat out;
    for (const Eigen::Vector2f& p : xy) {
        std::uint8_t* c = seen.At(p.cast<double>());
        if (c && !*c) {
            *c = 1;
            out.push_back(p);
        }
    }
    return out;
}

// Where the table was read and nothing of the object, over the footprint grown by `reach`:
// cells of `cell_m` holding a table reading and no footprint reading. A segment crossing one
// crosses seen free table.
class FreeTable {
public:
    FreeTable(const Points& table, const Flat& footprint, double cell_m, double reach)
        : raster_(Bounds(footprint, reach), cell_m), step_(0.5 * cell_m) {
        constexpr std::uint8_t kTable = 1, kObject = 2;
        for (const Eigen::Vector3f& t : table) {
            if (std::uint8_t* c = raster_.At(t.head<2>().cast<double>())) *c |= kTable;
        }
        for (const Eigen::Vector2f& p : footprint) {
            if (std::uint8_t* c = raster_.At(p.cast<double>())) *c |= kObject;
        }
        any_ = !table.empty();
    }

    // Whether the segment from a to b crosses a free cell.
    bool Crosses(const Eigen::Vector2d& a, const Eigen::Vector2d& b) const {
        if (!any_) return false;
        const int steps = static_cast<int>(std::ceil((b - a).norm() / step_));
        for (int i = 0; i <= steps; ++i) {
            const double t = steps > 0 ? static_cast<double>(i) / steps : 0.0;
            if (raster_.Get(a + t * (b - a)) == 1) return true;  // table and no object
        }
        return false;
    }

private:
    Raster<std::uint8_t> raster_;
    double step_;
    bool any_ = false;
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
    xy = Distinct(WithoutStrays(xy, links.link_m, links.stray_share), kDistinctM);
    if (xy.empty()) return {};  // nothing stands above the table
    const FreeTable free(table, xy, 0.5 * links.link_m, links.unread_reach_m);
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
