#include "pipeline/envelope/layer_marks.h"

#include <algorithm>
#include <cmath>
#include <utility>
#include <vector>

namespace boxd::envelope {

void MarkSlopesToReadHigh(CellGrid<LayerCell>* grid, double sigma, const EnvelopeConfig& config) {
    std::vector<LayerCell::Slope> slopes(grid->cells.size());
    for (std::size_t k = 0; k < grid->cells.size(); ++k) {
        const LayerCell& c = grid->cells[k];
        if (c.n < config.min_cell_points) continue;
        // Two surfaces sharing the cell (a ledge's edge: a wall and the ledge behind it) are no
        // slope, however a plane through both of them rises.
        double off_plane = 0.0;
        c.Facing(&off_plane);
        if (OnOnePlane(off_plane, sigma * sigma, c.n)) slopes[k] = c.BestSlope(sigma);
    }
    auto slope_at = [&](int i, int j) -> const LayerCell::Slope& {
        return slopes[static_cast<std::size_t>(grid->CellAt(i, j) - grid->cells.data())];
    };
    for (int j = 0; j < grid->nb; ++j) {
        for (int i = 0; i < grid->na; ++i) {
            const LayerCell::Slope& here = slope_at(i, j);
            if (!(here.rise > sigma)) continue;
            const Eigen::Vector2d down = -here.gradient.normalized();
            const int di = static_cast<int>(std::lround(std::sqrt(2.0) * down.x()));
            const int dj = static_cast<int>(std::lround(std::sqrt(2.0) * down.y()));
            const int ni = std::clamp(i + std::clamp(di, -1, 1), 0, grid->na - 1);
            const int nj = std::clamp(j + std::clamp(dj, -1, 1), 0, grid->nb - 1);
            const LayerCell::Slope& next = slope_at(ni, nj);
            if ((ni != i || nj != j) && next.rise > sigma &&
                next.gradient.normalized().dot(-down) > 0.5) {
                grid->CellAt(i, j)->high_end_above_mean_m = std::sqrt(3.0) * here.rise;
            }
        }
    }
}

// How many standard errors a cell's means must curve down by to mark a cap's top.
constexpr double kCurvedSigmas = 3.0;

void MarkCapTops(CellGrid<LayerCell>* grid, double sigma, const EnvelopeConfig& config) {
    const double layer = config.layer_sigmas * sigma;
    std::vector<double> cap(grid->cells.size(), 0.0);
    for (std::size_t k = 0; k < grid->cells.size(); ++k) {
        const LayerCell& c = grid->cells[k];
        if (c.n < config.min_cell_points || c.high_end_above_mean_m > 0.0) continue;
        const int i = static_cast<int>(k % static_cast<std::size_t>(grid->na));
        const int j = static_cast<int>(k / static_cast<std::size_t>(grid->na));
        // A cell's mean is known no better than the noise over its readings' count.
        auto mean_var = [sigma](const LayerCell& cell) {
            return std::max(cell.StdError() * cell.StdError(), sigma * sigma / cell.n);
        };
        double laplacian = 0.0, variance = 16.0 * mean_var(c);
        bool smooth = true;
        for (const auto& [di, dj] : {std::pair{-1, 0}, {1, 0}, {0, -1}, {0, 1}}) {
            const LayerCell* nb = grid->CellAt(i + di, j + dj);
            smooth = smooth && nb != nullptr && nb->n >= config.min_cell_points &&
                     std::abs(nb->Mean() - c.Mean()) <= layer;
            if (!smooth) break;
            laplacian += nb->Mean() - c.Mean();
            variance += mean_var(*nb);
        }
        // Curved down beyond the noise: a flat top's noisy means would otherwise crest at
        // every cell that came out high, and the highest of them is the one read.
        if (smooth && -laplacian > kCurvedSigmas * std::sqrt(variance)) cap[k] = -laplacian / 24.0;
    }
    for (std::size_t k = 0; k < cap.size(); ++k) grid->cells[k].cap_above_mean_m = cap[k];
}

void MarkRidgesToReadHigh(CellGrid<LayerCell>* grid, const EnvelopeConfig& config) {
    // Half a cell's width, evenly covered, has this variance across (the narrower way).
    const double half_cover = std::pow(std::min(grid->da, grid->db) / 2.0, 2) / 12.0;
    struct Spread {
        bool judged = false, level = false;
        double variance = 0.0;
    };
    std::vector<Spread> spread(grid->cells.size());
    for (std::size_t k = 0; k < grid->cells.size(); ++k) {
        const LayerCell& c = grid->cells[k];
        if (c.n < config.min_cell_points) continue;
        double noise_var = 0.0;
        c.Facing(&noise_var);
        const double variance = c.Variance() - noise_var;
        const double wander = 3.0 * SampleVarianceSe(noise_var, c.n);
        spread[k] = {true, variance <= wander && c.NarrowerExtentVariance() >= half_cover,
                     variance};
    }
    for (int j = 0; j < grid->nb; ++j) {
        for (int i = 0; i < grid->na; ++i) {
            LayerCell& c = *grid->CellAt(i, j);
            const Spread& here = spread[static_cast<std::size_t>(&c - grid->cells.data())];
            if (!here.judged || here.level || c.high_end_above_mean_m > 0.0 ||
                c.cap_above_mean_m > 0.0) {
                continue;
            }
            bool rim = false;
            for (int dj = -1; dj <= 1 && !rim; ++dj) {
                for (int di = -1; di <= 1 && !rim; ++di) {
                    const LayerCell* nb = grid->CellAt(i + di, j + dj);
                    if (nb == nullptr || nb == &c || nb->n < config.min_cell_points) continue;
                    const double apart = 2.0 * (nb->StdError() + c.StdError());
                    rim = nb->Mean() > c.Mean() + apart ||
                          (spread[static_cast<std::size_t>(nb - grid->cells.data())].level &&
                           nb->Mean() >= c.Mean() - apart);
                }
            }
            if (!rim) c.high_end_above_mean_m = std::sqrt(3.0 * here.variance);
        }
    }
}

}  // namespace boxd::envelope
