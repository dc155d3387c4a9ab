#pragma once
// Core: Exact nearest-neighbour lookup within a radius on a uniform grid: the hot loop of ICP,
// where every source point asks for its nearest target point within the correspondence gate.

#include <Eigen/Core>
#include <array>
#include <cstdint>
#include <vector>

#include "pipeline/core/point_cloud.h"

namespace boxd {

class NearestGrid {
public:
    NearestGrid() = default;
    // Buckets `points` into cubic cells of edge `cell_m`, grown when the bounding box would need
    // more than `max_cells` cells (0: 256 per point, at least 65536, at most 8M — the cell array
    // is dense). Queries are fastest when the search radius is near cell_m. Points that are not
    // finite are left out (they are nobody's neighbour).
    NearestGrid(const Points& points, float cell_m, std::size_t max_cells = 0);

    // Returns the index (into the constructor's points) of the nearest point within `max_dist`
    // of `p`, or -1 (also for a query that is not finite). Ties go to the lower index, so the
    // answer never depends on the layout.
    int Nearest(const Eigen::Vector3f& p, float max_dist) const;

    // One of KNearest's neighbours: its index into the constructor's points and its squared
    // distance to the query.
    struct Neighbour {
        float sqr_dist;
        int index;
    };

    // Fills `out` with the k points nearest to `p`, nearest first (ties: lower index first),
    // or with every point when there are fewer. Exact: the search grows from one cell until
    // the k-th nearest found lies within the radius it has covered.
    void KNearest(const Eigen::Vector3f& p, int k, std::vector<Neighbour>* out) const;

    float cell_m() const { return cell_; }

private:
    // Appends to `out` every point within `radius` of `p` (unordered).
    void Within(const Eigen::Vector3f& p, float radius, std::vector<Neighbour>* out) const;
    // The cells overlapping the cube of half-edge `radius` about `p`, clipped to the grid;
    // false when the cube misses the grid.
    bool CellRange(const Eigen::Vector3f& p, float radius, std::array<int, 6>* range) const;
    // Calls visit(slot) for every point (its slot in sorted_) of the cells CellRange finds.
    template <typename Visit>
    void ForEachNear(const Eigen::Vector3f& p, float radius, Visit&& visit) const {
        std::array<int, 6> c{};
        if (!CellRange(p, radius, &c)) return;
        for (int z = c[4]; z <= c[5]; ++z) {
            for (int y = c[2]; y <= c[3]; ++y) {
                const std::size_t row =
                    (static_cast<std::size_t>(z) * static_cast<std::size_t>(ny_) +
                     static_cast<std::size_t>(y)) *
                    static_cast<std::size_t>(nx_);
                const std::uint32_t end = start_[row + static_cast<std::size_t>(c[1]) + 1];
                for (std::uint32_t s = start_[row + static_cast<std::size_t>(c[0])]; s < end; ++s) {
                    visit(s);
                }
            }
        }
    }

    Eigen::Vector3f origin_ = Eigen::Vector3f::Zero();
    float cell_ = 0.0f;
    float inv_cell_ = 0.0f;
    int nx_ = 0, ny_ = 0, nz_ = 0;
    std::vector<std::uint32_t> start_;  // first slot of each cell in sorted_, plus an end mark
    std::vector<std::uint32_t> index_;  // original index of each slot
    Points sorted_;                     // the points grouped by cell
};

}  // namespace boxd
