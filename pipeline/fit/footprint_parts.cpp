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

// A reading of the footprint and how far it links (footprint_parts.h).
struct Reading {
    Eigen::Vector2f xy;
    float link;
};

// The readings of a surface seen obliquely lie farther apart along the view than across it, by
// 1 / sin of the elevation: twice at 30 degrees, the lowest a station's camera looks down at.
constexpr double kAlongViewStretch = 2.0;

std::int64_t Key(int x, int y) {
    return (static_cast<std::int64_t>(x) << 32) ^ static_cast<std::uint32_t>(y);
}

int Index(float v, double inv) { return static_cast<int>(std::floor(v * inv)); }

// A cell's readings are placed on a grid this many times finer: the footprint's sampling is
// read from how many of its sub-cells hold a reading, not from how many readings there are (the
// fusion keeps readings in clusters, a voxel's handful together).
constexpr int kSubCells = 4;

// The footprint without the lone readings at its edge, each reading with its link: `cell_m`, or
// where the cloud samples the footprint more sparsely (a cell of which k sub-cells hold readings
// is sampled every cell / √k on average; the best sampled of the reading's cell and its
// neighbours counts), that spacing stretched along the view.
std::vector<Reading> LinkedReadings(const Flat& xy, double cell_m, double stray_share) {
    const double inv = 1.0 / cell_m, sub_inv = kSubCells * inv;
    std::unordered_map<std::int64_t, int> count;
    std::unordered_map<std::int64_t, std::uint32_t> sub_cells;  // a bit per sub-cell
    for (const Eigen::Vector2f& p : xy) {
        const int x = Index(p.x(), inv), y = Index(p.y(), inv);
        ++count[Key(x, y)];
        const int sx = Index(p.x(), sub_inv) - kSubCells * x,
                  sy = Index(p.y(), sub_inv) - kSubCells * y;
        const int bit =
            std::clamp(sx, 0, kSubCells - 1) * kSubCells + std::clamp(sy, 0, kSubCells - 1);
        sub_cells[Key(x, y)] |= 1U << bit;
    }
    std::vector<double> counts;
    counts.reserve(count.size());
    for (const auto& [key, n] : count) counts.push_back(n);
    const double stray = stray_share * Median(std::move(counts));
    auto occupied = [&](int x, int y) { return count.count(Key(x, y)) > 0; };
    std::vector<Reading> kept;
    kept.reserve(xy.size());
    for (const Eigen::Vector2f& p : xy) {
        const int x = Index(p.x(), inv), y = Index(p.y(), inv);
        const bool edge = !occupied(x + 1, y) || !occupied(x - 1, y) || !occupied(x, y + 1) ||
                          !occupied(x, y - 1);
        if (edge && count[Key(x, y)] < stray) continue;
        // The best sampled cell round it: a cell the surface's edge only grazes is not sparse.
        int sampled = 0;
        for (int dx = -1; dx <= 1; ++dx) {
            for (int dy = -1; dy <= 1; ++dy) {
                auto it = sub_cells.find(Key(x + dx, y + dy));
                if (it != sub_cells.end())
                    sampled = std::max(sampled, __builtin_popcount(it->second));
            }
        }
        const double spacing = cell_m / std::sqrt(static_cast<double>(sampled));
        kept.push_back({p, static_cast<float>(std::max(cell_m, kAlongViewStretch * spacing))});
    }
    return kept;
}

// The readings sorted into square cells whose diagonal is the least link (any two readings of
// one cell are linked), and the union-find over the cells.
class LinkGrid {
public:
    LinkGrid(std::vector<Reading> readings, double link_m) : readings_(std::move(readings)) {
        inv_ = std::sqrt(2.0) / link_m;
        float widest = static_cast<float>(link_m);
        std::vector<std::pair<std::int64_t, int>> keyed(readings_.size());
        for (std::size_t i = 0; i < readings_.size(); ++i) {
            const Eigen::Vector2f& p = readings_[i].xy;
            keyed[i] = {Key(Index(p.x(), inv_), Index(p.y(), inv_)), static_cast<int>(i)};
            widest = std::max(widest, readings_[i].link);
        }
        // Cells that far apart may still hold readings within the widest link.
        reach_ = static_cast<int>(std::ceil(widest * inv_)) + 1;
        std::sort(keyed.begin(), keyed.end());
        std::vector<Reading> sorted(readings_.size());
        for (std::size_t i = 0; i < keyed.size(); ++i) {
            sorted[i] = readings_[static_cast<std::size_t>(keyed[i].second)];
            if (i == 0 || keyed[i].first != keyed[i - 1].first) {
                const Eigen::Vector2f& p = sorted[i].xy;
                index_[keyed[i].first] = static_cast<int>(cells_.size());
                cells_.push_back({Index(p.x(), inv_), Index(p.y(), inv_), static_cast<int>(i), 0});
            }
            cells_.back().end = static_cast<int>(i) + 1;
        }
        readings_ = std::move(sorted);
        parent_.resize(cells_.size());
        std::iota(parent_.begin(), parent_.end(), 0);
    }

    // Joins every two cells holding readings within their link of each other (the wider of the
    // two readings' links).
    void Link() {
        for (std::size_t c = 0; c < cells_.size(); ++c) {
            for (int dx = 0; dx <= reach_; ++dx) {
                for (int dy = -reach_; dy <= reach_; ++dy) {
                    if (dx == 0 && dy <= 0) continue;  // each pair once
                    auto it = index_.find(Key(cells_[c].x + dx, cells_[c].y + dy));
                    if (it == index_.end()) continue;
                    const int a = Find(static_cast<int>(c)), b = Find(it->second);
                    if (a != b && Near(cells_[c], cells_[static_cast<std::size_t>(it->second)])) {
                        parent_[static_cast<std::size_t>(a)] = b;
                    }
                }
            }
        }
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
        int x, y, begin, end;  // its readings are readings_[begin, end)
    };

    int Find(int c) {
        while (parent_[static_cast<std::size_t>(c)] != c) {
            auto& up = parent_[static_cast<std::size_t>(c)];
            up = parent_[static_cast<std::size_t>(up)];
            c = up;
        }
        return c;
    }

    bool Near(const Cell& a, const Cell& b) const {
        for (int i = a.begin; i < a.end; ++i) {
            for (int j = b.begin; j < b.end; ++j) {
                const Reading& p = readings_[static_cast<std::size_t>(i)];
                const Reading& q = readings_[static_cast<std::size_t>(j)];
                const double link = std::max(p.link, q.link);
                if ((p.xy - q.xy).cast<double>().squaredNorm() <= link * link) return true;
            }
        }
        return false;
    }

    std::vector<Reading> readings_;
    double inv_ = 1.0;
    int reach_ = 2;
    std::vector<Cell> cells_;
    std::unordered_map<std::int64_t, int> index_;
    std::vector<int> parent_;
};

}  // namespace

FootprintParts SeparateFootprint(const Points& points, double min_height_m, double link_m,
                                 double stray_share) {
    Flat xy;
    xy.reserve(points.size());
    for (const Eigen::Vector3f& p : points) {
        if (p.z() >= min_height_m) xy.emplace_back(p.x(), p.y());
    }
    LinkGrid grid(LinkedReadings(xy, link_m, stray_share), link_m);
    grid.Link();
    const double cell_area = 0.5 * link_m * link_m;
    FootprintParts parts;
    for (int cells : grid.PartCells()) {
        parts.area_m2.push_back(cells * cell_area);
        parts.total_m2 += cells * cell_area;
    }
    return parts;
}

}  // namespace boxd
