#include "pipeline/envelope/foot_band.h"

#include <cmath>
#include <optional>
#include <utility>
#include <vector>

#include "pipeline/envelope/wall_profile.h"

namespace boxd::envelope {

namespace {

// The rows of the wall's profile read above the band: five 12 mm rows, 60 mm of the wall.
constexpr int kProfileRows = 5;

// A row's outermost judged cell: its mean reach, less the median of the largest of as many
// noise draws as cells compete for it (the largest of many noisy means stands out by that much),
// its standard error and its readings' mean height.
using RowReach = ProfileRow;

// The outermost of a row's `na` cells holding at least `min_points` readings, by `reach`, and how
// many cells compete for it: those within two standard errors (`se`) of it.
template <class Cell, class Reach, class Se>
std::optional<std::pair<const Cell*, int>> Outermost(const Cell* row, int na, int min_points,
                                                     Reach reach, Se se) {
    const Cell* best = nullptr;
    for (int i = 0; i < na; ++i) {
        if (row[i].n >= min_points && (!best || reach(row[i]) > reach(*best))) best = &row[i];
    }
    if (!best) return std::nullopt;
    int contenders = 0;
    for (int i = 0; i < na; ++i) {
        contenders += row[i].n >= min_points &&
                      reach(row[i]) >= reach(*best) - 2.0 * (se(row[i]) + se(*best));
    }
    return std::pair{best, contenders};
}

std::optional<RowReach> OutermostInRow(const CellGrid<LayerCell>& layer, int row,
                                       const EnvelopeConfig& config) {
    const auto outermost = Outermost(
        &layer.cells[static_cast<std::size_t>(row) * static_cast<std::size_t>(layer.na)], layer.na,
        config.min_cell_points, [](const LayerCell& c) { return c.Mean(); },
        [](const LayerCell& c) { return c.StdError(); });
    if (!outermost) return std::nullopt;
    const auto [best, contenders] = *outermost;
    return RowReach{best->Mean() - MedianOfLargest(contenders) * best->StdError(), best->StdError(),
                    best->Centroid().y()};
}

// Returns the lowest of `rows` (`row_height` apart) that are one wall: the profile ends below
// the first row that departs from the line through the rows under it by more than a row's
// height. Between them the surface runs nearer level than upright against that line: a ledge,
// and the rows above it are another wall (a small parcel standing or strapped on a larger one),
// which a line through both ran out to the table as far as the ledge is deep. A flank's rows,
// plane or bending, stay within their noise and curvature of it. Where two rows stand from the
// departing one up, the step is seen from above too: their line, carried down to the row under
// them, departs from it as far. A flank's lowest rows read slivers at their cells' feet, their
// heights a few millimetres apart, and a line through two of them ran 3 times gentler than the
// wedge it read: its third row stood 11 mm off that line, and the wedge had no foot.
std::vector<RowReach> OneWall(std::vector<RowReach> rows, double row_height) {
    auto departs = [row_height](const std::vector<RowReach>& line_rows, const RowReach& row) {
        const auto line = FitProfile(line_rows, 1);
        return line && std::abs(row.s - (line->at_table - line->slope * row.z)) > row_height;
    };
    for (std::size_t k = 2; k < rows.size(); ++k) {
        const auto first = rows.begin();
        const auto at = first + static_cast<std::ptrdiff_t>(k);
        if (!departs(std::vector<RowReach>(first, at), rows[k])) continue;
        if (k + 2 <= rows.size() && !departs(std::vector<RowReach>(at, at + 2), rows[k - 1])) {
            continue;
        }
        rows.resize(k);
        break;
    }
    return rows;
}

// Whether the rows between the band and row `first` hold fewer readings than one judged cell:
// nothing read the wall there (a few strays aside), rather than too few readings to judge a
// cell (the narrow foot of a lying tube's round end).
bool NothingReadBelow(const CellGrid<LayerCell>& layer, int first, const EnvelopeConfig& config) {
    long readings = 0;
    for (int j = 0; j < first; ++j) {
        if (layer.b0 + (j + 1) * layer.db <= config.min_z_m + 1e-9) continue;  // within the band
        for (int i = 0; i < layer.na; ++i) {
            readings += layer.cells[static_cast<std::size_t>(j) * layer.na + i].n;
        }
    }
    return readings < config.min_cell_points;
}

// A column's readings of one row within the window about the wall's line: their count, sums of
// along and up, and of their offsets from the line and its squares.
struct WindowCell {
    int n = 0;
    double along = 0.0, up = 0.0, r = 0.0, rr = 0.0;
    double Offset() const { return r / n; }
    double Se() const {
        const double var = (rr - r * r / n) / std::max(1, n - 1);
        return std::sqrt(std::max(var, 0.0) / n);
    }
};

// The `count` rows from `first` read again (the header's last paragraph): each column's readings
// of the row within `window` along the direction of `line`, either side; in each row the column
// standing farthest out of the line, corrected as OutermostInRow corrects its cell. Stops at the
// first row no column of which holds enough readings.
std::vector<RowReach> ReadRowsAgain(const CellGrid<LayerCell>& layer, const WallReadings& readings,
                                    int first, int count, const ProfileFit& line, double window,
                                    const EnvelopeConfig& config) {
    const int na = layer.na;
    std::vector<WindowCell> cells(static_cast<std::size_t>(count) * static_cast<std::size_t>(na));
    for (const Eigen::Vector3d& p : readings.across_up_along) {
        const int j = static_cast<int>(std::floor((p.y() - layer.b0) / layer.db)) - first;
        const int i = static_cast<int>(std::floor((readings.sign * p.x() - layer.a0) / layer.da));
        if (j < 0 || j >= count || i < 0 || i >= na) continue;
        const double along = readings.sign * p.z();
        const double r = along - (line.at_table - line.slope * p.y());
        if (std::abs(r) > window) continue;
        WindowCell& c = cells[static_cast<std::size_t>(j) * na + i];
        ++c.n;
        c.along += along;
        c.up += p.y();
        c.r += r;
        c.rr += r * r;
    }
    std::vector<RowReach> rows;
    for (int j = 0; j < count; ++j) {
        const auto outermost = Outermost(
            &cells[static_cast<std::size_t>(j) * na], na, config.min_cell_points,
            [](const WindowCell& c) { return c.Offset(); },
            [](const WindowCell& c) { return c.Se(); });
        if (!outermost) break;
        const auto [best, contenders] = *outermost;
        rows.push_back({best->along / best->n - MedianOfLargest(contenders) * best->Se(),
                        best->Se(), best->up / best->n});
    }
    return rows;
}

}  // namespace

FootReach ExtrapolateFoot(const CellGrid<LayerCell>& layer, const WallReadings& readings,
                          double sigma, const EnvelopeConfig& config) {
    FootReach out;
    // The lowest row holding a judged cell: the first above the band, or higher where nothing
    // read the wall's foot (foot_free_space.h says how far it may go).
    int first = -1;
    for (int j = 0; j < layer.nb && first < 0; ++j) {
        if (OutermostInRow(layer, j, config)) first = j;
    }
    if (first < 0) return out;
    // A wall read below its lowest judged row, too sparsely to judge (the narrow foot of a lying
    // tube's round end), or standing on something (an overhang), has no foot to extend.
    const bool at_band = layer.b0 + first * layer.db <= config.min_z_m + 1e-9;
    out.above_band = !at_band;
    out.raised = !at_band && NothingReadBelow(layer, first, config);
    if (!at_band && !out.raised) return out;
    // The wall's profile: its lowest rows, one after another, as far as kProfileRows.
    std::vector<RowReach> rows;
    for (int j = first; j < layer.nb && j < first + kProfileRows; ++j) {
        const auto r = OutermostInRow(layer, j, config);
        if (!r) break;
        rows.push_back(*r);
    }
    rows = OneWall(std::move(rows), layer.db);
    if (rows.size() < 3 || !OutwardLine(rows)) return out;
    // Read again about the line, twice: the first line stands out by the slivers' lean.
    for (int pass = 0; pass < 2; ++pass) {
        const ProfileFit line = *FitProfile(rows, 1);
        const double window = config.layer_sigmas * sigma * std::hypot(1.0, line.slope);
        auto again = ReadRowsAgain(layer, readings, first, static_cast<int>(rows.size()), line,
                                   window, config);
        if (again.size() != rows.size()) break;
        rows = std::move(again);
    }
    const auto line = OutwardLine(rows);
    if (!line) return out;
    out.slope = line->slope;
    const ProfileFoot foot = FootOfLine(rows, *line);
    out.reach = foot.reach;
    out.se = foot.se;
    return out;
}

}  // namespace boxd::envelope
