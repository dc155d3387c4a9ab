#include "pipeline/envelope/face_windows.h"

#include <Eigen/Dense>
#include <algorithm>
#include <cmath>
#include <set>
#include <utility>

#include "pipeline/envelope/surface_cells.h"

namespace boxd::envelope {

namespace {

constexpr int kSquareSides[] = {2, 3, 4, 6, 8, 12, 16, 24, 32};
constexpr int kWidestBand = 3;
// A window is judged with at least this share of its cells judged.
constexpr double kJudgedShare = 0.75;
// A cell's own variance, at least (a micrometre squared): its weight in a window is the inverse.
constexpr double kLeastVariance = 1e-12;
// The face's cells' plane leaves out, in its second fit, cells this far off its first.
constexpr double kTrimSigmas = 3.0;

// Sums over a grid's rectangles in constant time: the table holds, at each corner, the sum over
// the cells below and left of it.
class Table {
public:
    Table(int columns, int rows)
        : columns_(columns),
          rows_(rows),
          sum_(static_cast<std::size_t>((columns + 1) * (rows + 1)), 0.0) {}

    // Adds x to the cell in `column`, `row`, if the grid has it.
    void Add(int column, int row, double x) {
        if (column < 0 || row < 0 || column >= columns_ || row >= rows_) return;
        sum_[Index(column + 1, row + 1)] += x;
    }
    void Integrate() {
        for (int y = 1; y <= rows_; ++y) {
            for (int x = 1; x <= columns_; ++x) {
                sum_[Index(x, y)] +=
                    sum_[Index(x - 1, y)] + sum_[Index(x, y - 1)] - sum_[Index(x - 1, y - 1)];
            }
        }
    }
    // The sum over the `w` x `h` cells whose lowest corner is (x, y).
    double Sum(int x, int y, int w, int h) const {
        return sum_[Index(x + w, y + h)] - sum_[Index(x, y + h)] - sum_[Index(x + w, y)] +
               sum_[Index(x, y)];
    }

private:
    std::size_t Index(int x, int y) const {
        return static_cast<std::size_t>(y * (columns_ + 1) + x);
    }
    int columns_, rows_;
    std::vector<double> sum_;
};

struct Window {
    double n = 0.0, mean = 0.0, se = 0.0;      // its judged cells, their mean and its error
    double above_cells = 0.0, above_se = 0.0;  // the mean over the cells' plane, its error
    double cell_se = 0.0;                      // its cells' own errors, their root mean square
};

// The face as its cells read it: a plane over the grid, offset(column, row) = c0 + c1 column
// + c2 row, fitted to the cells' offsets by weighted least squares, then again without the
// cells it leaves more than kTrimSigmas standard errors off (a strap's or a label's above it, a
// rounded edge's below), and the variance of its value at a place.
class CellsPlane {
public:
    CellsPlane(const std::vector<GridCell>& cells, double shared_var) {
        auto var = [&](const GridCell& c) {
            return std::max(c.own_var + shared_var / std::max(1, c.views), kLeastVariance);
        };
        std::vector<bool> kept(cells.size(), true);
        for (int pass = 0; pass < 2; ++pass) {
            Eigen::Matrix3d normal = Eigen::Matrix3d::Zero();
            Eigen::Vector3d rhs = Eigen::Vector3d::Zero();
            for (std::size_t i = 0; i < cells.size(); ++i) {
                if (!kept[i]) continue;
                const Eigen::Vector3d t = Terms(cells[i].column, cells[i].row);
                normal += t * t.transpose() / var(cells[i]);
                rhs += t * cells[i].offset_m / var(cells[i]);
            }
            const Eigen::FullPivLU<Eigen::Matrix3d> lu(normal);
            if (!lu.isInvertible()) return;
            coefficients_ = lu.solve(rhs);
            inverse_ = lu.inverse();
            for (std::size_t i = 0; i < cells.size(); ++i) {
                kept[i] = std::abs(cells[i].offset_m - At(cells[i].column, cells[i].row)) <=
                          kTrimSigmas * std::sqrt(var(cells[i]));
            }
        }
    }
    double At(double column, double row) const { return coefficients_.dot(Terms(column, row)); }
    double Variance(double column, double row) const {
        const Eigen::Vector3d t = Terms(column, row);
        return t.dot(inverse_ * t);
    }

private:
    static Eigen::Vector3d Terms(double column, double row) { return {1.0, column, row}; }
    Eigen::Vector3d coefficients_ = Eigen::Vector3d::Zero();
    Eigen::Matrix3d inverse_ = Eigen::Matrix3d::Zero();
};

// The windows' statistics over a face's grid.
class FaceSums {
public:
    FaceSums(const std::vector<GridCell>& cells, const std::vector<ViewCell>& readings, int views,
             int columns, int rows, double shared_var, const CellsPlane& plane)
        : offset_(columns, rows),
          count_(columns, rows),
          own_(columns, rows),
          weight_(columns, rows),
          weighted_column_(columns, rows),
          weighted_row_(columns, rows),
          inverse_views_(columns, rows),
          shared_var_(shared_var),
          plane_(plane) {
        for (const GridCell& c : cells) {
            const double weight = 1.0 / std::max(c.own_var, kLeastVariance);
            offset_.Add(c.column, c.row, weight * c.offset_m);
            count_.Add(c.column, c.row, 1.0);
            own_.Add(c.column, c.row, c.own_var);
            weight_.Add(c.column, c.row, weight);
            weighted_column_.Add(c.column, c.row, weight * c.column);
            weighted_row_.Add(c.column, c.row, weight * c.row);
            inverse_views_.Add(c.column, c.row, 1.0 / std::max(1, c.views));
        }
        for (Table* t : {&offset_, &count_, &own_, &weight_, &weighted_column_, &weighted_row_,
                         &inverse_views_}) {
            t->Integrate();
        }
        std::vector<int> slot(static_cast<std::size_t>(std::max(views, 1)), -1);
        for (const ViewCell& r : readings) {
            if (r.view < 0 || r.view >= views) continue;
            int& s = slot[static_cast<std::size_t>(r.view)];
            if (s < 0) {
                s = static_cast<int>(view_sum_.size());
                view_sum_.emplace_back(columns, rows);
                view_count_.emplace_back(columns, rows);
            }
            view_sum_[static_cast<std::size_t>(s)].Add(r.column, r.row, r.sum_m);
            view_count_[static_cast<std::size_t>(s)].Add(r.column, r.row, r.readings);
        }
        for (Table& t : view_sum_) t.Integrate();
        for (Table& t : view_count_) t.Integrate();
    }

    Window At(int x, int y, int w, int h) const {
        Window out;
        out.n = count_.Sum(x, y, w, h);
        if (out.n < 1.0) return out;
        const double weight = weight_.Sum(x, y, w, h);
        out.mean = offset_.Sum(x, y, w, h) / weight;
        const double modelled = shared_var_ * inverse_views_.Sum(x, y, w, h) / out.n + 1.0 / weight;
        // The views' own spread over the window.
        CellStats views;
        for (std::size_t v = 0; v < view_sum_.size(); ++v) {
            const double r = view_count_[v].Sum(x, y, w, h);
            if (r >= 1.0) views.Add(view_sum_[v].Sum(x, y, w, h) / r);
        }
        const double spread = views.n >= 2 ? views.Variance() / views.n : 0.0;
        out.se = std::sqrt(std::max({modelled, spread, 0.0}));
        out.cell_se = std::sqrt(
            (own_.Sum(x, y, w, h) + shared_var_ * inverse_views_.Sum(x, y, w, h)) / out.n);
        const double column = weighted_column_.Sum(x, y, w, h) / weight;
        const double row = weighted_row_.Sum(x, y, w, h) / weight;
        out.above_cells = out.mean - plane_.At(column, row);
        out.above_se = std::sqrt(out.se * out.se + plane_.Variance(column, row));
        return out;
    }

private:
    Table offset_, count_, own_, weight_, weighted_column_, weighted_row_, inverse_views_;
    std::vector<Table> view_sum_, view_count_;
    double shared_var_;
    const CellsPlane& plane_;
};

// The windows' shapes on a grid of `columns` x `rows`: the squares that fit, and the bands
// across the whole face, each once.
std::vector<std::pair<int, int>> Shapes(int columns, int rows) {
    std::set<std::pair<int, int>> shapes;
    for (int s : kSquareSides) {
        if (s <= columns && s <= rows) shapes.insert({s, s});
    }
    for (int k = 1; k <= kWidestBand; ++k) {
        if (k < columns) shapes.insert({k, rows});
        if (k < rows) shapes.insert({columns, k});
    }
    return {shapes.begin(), shapes.end()};
}

struct Placed {
    int x, y;
    Window w;
};

}  // namespace

std::optional<WindowReach> WindowStandingOut(const std::vector<GridCell>& cells,
                                             const std::vector<ViewCell>& readings, int views,
                                             int columns, int rows, double shared_var,
                                             double false_alarm, double threshold_m) {
    if (cells.empty() || columns < 1 || rows < 1) return std::nullopt;
    // The face as its cells read it (face_windows.h): a window stands out of it and of the
    // face's plane, which the cells' offsets are measured from.
    const CellsPlane plane(cells, shared_var);
    const FaceSums sums(cells, readings, views, columns, rows, shared_var, plane);
    const auto shapes = Shapes(columns, rows);
    // Every window of every shape with three quarters of its cells judged: all count for the
    // confidence.
    std::vector<std::vector<Placed>> placed(shapes.size());
    int m = 0;
    for (std::size_t s = 0; s < shapes.size(); ++s) {
        const auto [w, h] = shapes[s];
        for (int y = 0; y + h <= rows; ++y) {
            for (int x = 0; x + w <= columns; ++x) {
                const Window win = sums.At(x, y, w, h);
                if (win.n < 2.0 || win.n < kJudgedShare * w * h || !(win.se > 0.0)) continue;
                placed[s].push_back({x, y, win});
                ++m;
            }
        }
    }
    if (m == 0) return std::nullopt;
    const double k = UpperNormalQuantile(false_alarm / m);
    std::optional<WindowReach> best;
    for (std::size_t s = 0; s < shapes.size(); ++s) {
        const auto [w, h] = shapes[s];
        std::vector<const Placed*> out;
        for (const Placed& p : placed[s]) {
            if (p.w.mean - k * p.w.se > threshold_m &&
                p.w.above_cells - k * p.w.above_se > threshold_m) {
                out.push_back(&p);
            }
        }
        if (out.empty()) continue;
        const Placed* top = *std::max_element(
            out.begin(), out.end(), [](auto* a, auto* b) { return a->w.mean < b->w.mean; });
        // The contenders overlap: they are as many draws as windows fit in what they cover.
        std::vector<const Placed*> contenders;
        std::vector<bool> covered(static_cast<std::size_t>(columns * rows), false);
        for (const Placed* p : out) {
            if (p->w.mean < top->w.mean - 2.0 * (p->w.se + top->w.se)) continue;
            contenders.push_back(p);
            for (int y = p->y; y < p->y + h; ++y) {
                for (int x = p->x; x < p->x + w; ++x) {
                    covered[static_cast<std::size_t>(y * columns + x)] = true;
                }
            }
        }
        const auto area = static_cast<double>(std::count(covered.begin(), covered.end(), true));
        const double z =
            MedianOfLargest(std::max(1, static_cast<int>(std::lround(area / (w * h)))));
        for (const Placed* p : contenders) {
            const double reach = p->w.mean - z * p->w.se;
            if (!best || reach > best->excess_m) {
                best =
                    WindowReach{reach, std::max(p->w.se, p->w.cell_se), static_cast<int>(p->w.n)};
            }
        }
    }
    return best;
}

}  // namespace boxd::envelope
