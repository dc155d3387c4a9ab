#include "pipeline/envelope/face_envelope.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <unordered_map>
#include <unordered_set>
#include <utility>
#include <vector>

#include "pipeline/core/student_t.h"
#include "pipeline/envelope/bowed_face.h"
#include "pipeline/envelope/face_windows.h"
#include "pipeline/envelope/leaning_face.h"
#include "pipeline/envelope/surface_cells.h"
#include "pipeline/fit/face_choice.h"
#include "pipeline/views/depth_rounding.h"

namespace boxd::envelope {

namespace {

// The views (each a sample of its mean) a cell needs to be judged. A cell standing out on its
// own (a strap, a label: ReadExcess, ReadPatches) takes four: three views that agree on an
// ideal box's cells by a vertical edge, where one of them sees the face at grazing, can put
// two such cells 0.67 mm out of the plane (a 353 x 349 mm box, 12 poses of 6 frames). The
// whole face bowing out (BowedFaceReach) takes three: a smooth bow over the face is not two
// cells by its edge, and with four a face only three views see (12 poses, a camera 39 degrees
// up) kept its edges and lost its middle, so a side bulging 4.9 mm read at its mean plane,
// 2.5 mm in.
constexpr int kCellViews = 4;
constexpr int kBowCellViews = 3;

// A face is judged flat or not from at least this many cells seen by two views or more.
constexpr int kMinFlatnessCells = 10;

// One face's cells, each with its points' offsets from the face plane kept per view: the views
// are the independent samples (a view's neighbouring readings share its registration error and
// its sensor's disparity steps, so its points are not).
struct FaceCells {
    int views = 1;
    int na = 1;                 // cells across the face's grid: a cell's key is row * na + column
    int nb = 1;                 // cells up the face's grid
    double da = 1.0, db = 1.0;  // the cells' size across and up the face
    double b0 = 0.0;            // where the grid's rows start up the face
    double height = 0.0;        // a side face's height (the top: 0, no lean is read)
    std::unordered_map<std::size_t, CellStats> cell_view;  // key cell * views + view
    std::vector<CellStats> view_plane;                     // per view: offsets near the plane

    // A cell's column and row on the face's grid.
    std::pair<int, int> ColumnRow(std::size_t cell) const {
        return {static_cast<int>(cell % static_cast<std::size_t>(na)),
                static_cast<int>(cell / static_cast<std::size_t>(na))};
    }

    // A cell judged for standing out: its mean over the views' means and its standard error.
    struct Judged {
        std::size_t key;
        CellStats st;
        double se;
    };

    // The face's cells, each a mean over its views' means, and the views' spread pooled over the
    // face. The fused cloud keeps a pixel in nine, so a view holds a handful of readings in a
    // cell, often one or two where it sees the face obliquely: every view that read the cell is
    // a sample (the pooled spread is the spread of such samples), or a face's middle, where a
    // bulge crests, would go unjudged.
    struct Pool {
        std::unordered_map<std::size_t, CellStats> cells;
        std::unordered_map<std::size_t, double> inverse_counts;  // per cell: Σ 1/r over views
        int dof = 0, total = 0, within_dof = 0;
        double spread = 0.0, noise = 0.0, shared = 0.0;
        bool Pooled() const { return dof >= 10; }
    };

    Pool PoolViews(double point_sigma) const {
        Pool p;
        for (const auto& [key, st] : cell_view) {
            const std::size_t cell = key / static_cast<std::size_t>(views);
            p.cells[cell].Add(st.Mean());
            p.inverse_counts[cell] += 1.0 / st.n;
        }
        double pooled = 0.0, within = 0.0, inverse_sum = 0.0;
        int samples = 0;
        for (const auto& [cell, st] : p.cells) {
            if (st.n < 2) continue;
            pooled += st.sum_sq - st.sum * st.sum / st.n;
            p.dof += st.n - 1;
            inverse_sum += p.inverse_counts.at(cell);
            samples += st.n;
        }
        for (const auto& [key, st] : cell_view) {
            p.total += st.n;
            if (st.n < 2) continue;
            within += st.sum_sq - st.sum * st.sum / st.n;
            p.within_dof += st.n - 1;
        }
        // Without a second view of any cell (one pose), the within-view noise of a cell's mean,
        // its readings counted as a tenth as many independent ones.
        p.spread = p.Pooled() ? std::sqrt(pooled / p.dof) : point_sigma;
        // A view's mean of a cell errs by what the view shares over the face (its registration,
        // its plane) and by its readings' noise over their count r: var = shared + noise / r.
        // The pooled spread mixes views of many readings with views of one or two; a cell whose
        // views read it with fewer than the face's usual count is known worse than the spread
        // says, one read with more better. Both parts from the face: the readings' scatter
        // within a view's cell, and what of the spread that leaves.
        p.noise = p.within_dof >= 10 ? within / p.within_dof : 0.0;
        p.shared = samples > 0
                       ? std::max(0.0, p.spread * p.spread - p.noise * inverse_sum / samples)
                       : 0.0;
        return p;
    }

    // The cells judged for standing out, each with its standard error. A cell is judged from
    // three views on (its own scatter then has two degrees of freedom to check the modelled
    // error against); see kCellViews for which reading takes which. A cell whose views scatter
    // more than the face's do (an edge some views see at grazing incidence, where the lateral
    // noise throws readings off the face) is known no better than its own scatter says.
    static std::vector<Judged> Judge(const Pool& p) {
        std::vector<Judged> judged;
        for (const auto& [cell, st] : p.cells) {
            if (st.n < kBowCellViews && p.Pooled()) continue;
            const double own = st.n >= 2 ? st.StdError() : 0.0;
            const double modelled =
                p.within_dof >= 10 ? std::sqrt(p.shared / st.n +
                                               p.noise * p.inverse_counts.at(cell) / (st.n * st.n))
                                   : p.spread / std::sqrt(st.n);
            const double single =
                p.spread / std::sqrt(std::max(1.0, p.total / 10.0 / p.cells.size()));
            judged.push_back({cell, st, p.Pooled() ? std::max(modelled, own) : single});
        }
        return judged;
    }

    // Flatness: the cells seen by two views or more, their means about the plane against their
    // own standard errors (chi-square per cell: about 1 for a flat face); NaN when too few.
    static double Flatness(const Pool& p) {
        if (!p.Pooled()) return std::numeric_limits<double>::quiet_NaN();
        double chi2 = 0.0;
        int tested = 0;
        for (const auto& [cell, st] : p.cells) {
            if (st.n < 2) continue;
            const double r = st.Mean() / (p.spread / std::sqrt(st.n));
            chi2 += r * r;
            ++tested;
        }
        return tested >= kMinFlatnessCells ? chi2 / tested
                                           : std::numeric_limits<double>::quiet_NaN();
    }

    // `point_sigma`: a reading's noise about the face, at least a floor; `reading_sigma`: as the
    // box fit read it (BoxFit::face_sigma_m).
    FaceResult Evaluate(const EnvelopeConfig& config, double point_sigma,
                        double reading_sigma) const {
        const Pool pool = PoolViews(point_sigma);
        const std::vector<Judged> judged = Judge(pool);
        // The plane's offset as each view sees it: their spread is the registration's and the
        // noise's contribution to the face's position.
        CellStats offsets;
        for (const CellStats& v : view_plane) {
            if (v.n >= 4 * config.min_cell_points) offsets.Add(v.Mean());
        }
        FaceResult out;
        if (const double flat = Flatness(pool); !std::isnan(flat)) out.flatness = flat;
        out.view_spread_m = offsets.n >= 2 ? offsets.StdError() * std::sqrt(offsets.n) : 0.0;
        // The views' own scatter, without CellStats' floor (a face's offset is the mean of
        // thousands of readings per view), widened for the few views it is estimated from.
        out.offset_se_m =
            offsets.n >= 2 ? WidenedForSamples(std::sqrt(offsets.Variance() / offsets.n), offsets.n)
                           : pool.spread / std::sqrt(std::max<std::size_t>(1, pool.cells.size()));
        std::vector<Judged> many;  // the cells seen by kCellViews views or more
        for (const Judged& c : judged) {
            if (c.st.n >= kCellViews || !pool.Pooled()) many.push_back(c);
        }
        ReadExcess(many, config, out.view_spread_m, &out);
        ReadBow(judged, config, &out);
        if (pool.Pooled()) ReadPatches(many, pool.shared, config, &out);
        ReadLean(judged, OneDepthRoundingSigma(config.depth_unit_m, reading_sigma), &out);
        return out;
    }
    // A side face leaning out towards the table or the top (leaning_face.h); a row known no
    // better than `row_floor_m`.
    void ReadLean(const std::vector<Judged>& judged, double row_floor_m, FaceResult* out) const {
        if (!(height > 0.0)) return;
        std::vector<FaceProfileCell> cells;
        cells.reserve(judged.size());
        for (const Judged& c : judged) {
            const auto row = static_cast<double>(c.key / static_cast<std::size_t>(na));
            cells.push_back({b0 + (row + 0.5) * db, c.st.Mean(), c.se});
        }
        const auto lean = LeaningFaceReach(cells, db, height, row_floor_m);
        if (lean && lean->reach > out->excess_m) {
            out->excess_m = lean->reach;
            out->excess_se_m = lean->se;
        }
    }

    // A panel bowing out smoothly shows as a whole face (bowed_face.h).
    void ReadBow(const std::vector<Judged>& judged, const EnvelopeConfig& config,
                 FaceResult* out) const {
        std::vector<FaceCell> face;
        face.reserve(judged.size());
        for (const Judged& c : judged) {
            const auto col = static_cast<double>(c.key % static_cast<std::size_t>(na));
            const auto row = static_cast<double>(c.key / static_cast<std::size_t>(na));
            face.push_back({col * da, row * db, c.st.Mean(), c.se});
        }
        const auto bow = BowedFaceReach(face, config.false_alarm, out->view_spread_m);
        if (bow && bow->excess_m > out->excess_m) {
            out->excess_m = bow->excess_m;
            out->excess_se_m = bow->se_m;
        }
    }

    // A band or a patch wider than a cell (face_windows.h), where the views' spread is known:
    // `shared` is the variance a view's mean of a cell shares with its other cells.
    void ReadPatches(const std::vector<Judged>& judged, double shared, const EnvelopeConfig& config,
                     FaceResult* out) const {
        std::vector<GridCell> grid;
        grid.reserve(judged.size());
        for (const Judged& c : judged) {
            const auto [col, row] = ColumnRow(c.key);
            grid.push_back(
                {col, row, c.st.Mean(), std::max(0.0, c.se * c.se - shared / c.st.n), c.st.n});
        }
        std::vector<ViewCell> readings;
        readings.reserve(cell_view.size());
        const auto nv = static_cast<std::size_t>(views);
        for (const auto& [key, st] : cell_view) {
            const auto [col, row] = ColumnRow(key / nv);
            readings.push_back({col, row, static_cast<int>(key % nv), st.sum, st.n});
        }
        const auto patch = WindowStandingOut(grid, readings, views, na, nb, shared,
                                             config.false_alarm, out->view_spread_m);
        if (patch && patch->excess_m > out->excess_m) {
            out->excess_m = patch->excess_m;
            out->excess_se_m = patch->se_m;
        }
    }

    // Detection: a cell stands out when its lower bound passes the plane, with the Bonferroni
    // confidence over all the face's cells, by more than the views' spread about the plane
    // (views that disagree about where the face is, on a miscalibrated station or a flexing
    // object, make cells stand out that are no surface of the object), and a neighbouring cell
    // stands out too: whatever stands out of a parcel's face (a bulge, a strap, a label) is
    // wider than a cell, and a lone cell is a few views' artefact. The excess is read from the
    // cells that could be the farthest out (within two standard errors of the farthest): the
    // largest of their means, less the median of the largest of that many noise draws.
    void ReadExcess(const std::vector<Judged>& judged, const EnvelopeConfig& config,
                    double threshold, FaceResult* out) const {
        const int m = static_cast<int>(judged.size());
        if (m == 0) return;
        const double k = UpperNormalQuantile(config.false_alarm / m);
        std::unordered_set<std::size_t> alone;
        for (const Judged& c : judged) {
            if (c.st.Mean() - k * c.se > threshold) alone.insert(c.key);
        }
        // Standing out beside a neighbour that does too, decided once per cell.
        std::vector<bool> out_flags(judged.size(), false);
        const Judged* top = nullptr;
        for (std::size_t n = 0; n < judged.size(); ++n) {
            const Judged& c = judged[n];
            if (alone.count(c.key) == 0) continue;
            const long key = static_cast<long>(c.key), col = key % na;
            for (long dj = -1; dj <= 1 && !out_flags[n]; ++dj) {
                for (long di = -1; di <= 1; ++di) {
                    const long other = key + dj * na + di;
                    if ((di != 0 || dj != 0) && col + di >= 0 && col + di < na && other >= 0 &&
                        alone.count(static_cast<std::size_t>(other)) != 0) {
                        out_flags[n] = true;
                        break;
                    }
                }
            }
            if (out_flags[n] && (top == nullptr || c.st.Mean() > top->st.Mean())) top = &c;
        }
        if (top == nullptr) return;
        auto competes = [&](std::size_t n) {
            return out_flags[n] &&
                   judged[n].st.Mean() >= top->st.Mean() - 2.0 * (judged[n].se + top->se);
        };
        int contenders = 0;
        for (std::size_t n = 0; n < judged.size(); ++n) contenders += competes(n) ? 1 : 0;
        const double z = MedianOfLargest(contenders);
        for (std::size_t n = 0; n < judged.size(); ++n) {
            if (!competes(n)) continue;
            const Judged& c = judged[n];
            const double excess = c.st.Mean() - z * c.se;
            if (excess > out->excess_m) {
                out->excess_m = excess;
                out->excess_se_m = c.se;
            }
        }
    }
};

}  // namespace

std::array<FaceResult, 5> FaceEnvelopes(const FusedCloud& cloud, const BoxFit& box, int views,
                                        const EnvelopeConfig& config) {
    const Eigen::Vector2d a = box.length_axis, b(-a.y(), a.x());
    const double hl = box.length_m / 2.0, hw = box.width_m / 2.0, h = box.height_m;
    const double m =
        EdgeMargin(config.edge_margin_m, std::min(box.width_m, box.height_m), box.rounded_margin_m);
    const double inward = std::max(config.inward_band_sigmas * box.face_sigma_m, 0.004);
    using Grid = CellGrid<CellStats>;
    std::array<Grid, 5> grids = {
        Grid(-hw + m, hw - m, m, h - m, config.cell_along_m, config.cell_height_m),
        Grid(-hw + m, hw - m, m, h - m, config.cell_along_m, config.cell_height_m),
        Grid(-hl + m, hl - m, m, h - m, config.cell_along_m, config.cell_height_m),
        Grid(-hl + m, hl - m, m, h - m, config.cell_along_m, config.cell_height_m),
        Grid(-hl + m, hl - m, -hw + m, hw - m, config.cell_along_m, config.cell_along_m)};
    const int nv = std::max(views, 1);
    std::array<FaceCells, 5> faces;
    for (FaceCells& f : faces) {
        f.views = nv;
        f.view_plane.resize(static_cast<std::size_t>(nv));
    }
    for (std::size_t f = 0; f < 5; ++f) {
        faces[f].na = grids[f].na;
        faces[f].nb = grids[f].nb;
        faces[f].da = grids[f].da;
        faces[f].db = grids[f].db;
        faces[f].b0 = grids[f].b0;
        faces[f].height = f < 4 ? h : 0.0;
    }
    // Every reading, as the face fits read them (fusion.h): the support test's voxels keep the
    // readings on one side of a voxel wall and drop the thinner layer on the other, and a face
    // that runs at a slight angle to the grid crosses the walls periodically. Its kept readings
    // ripple: on a single Kinect frame a pose the sides of ideal boxes yawed 2 and 6 degrees
    // read half a millimetre in and out every 172 and 57 mm (6 mm over the sine of the yaw),
    // the same in every view, and the ripple's crests stood out as a label (+1.7 and +2.1 mm).
    for (std::size_t i = 0; i < cloud.unfiltered.size(); ++i) {
        const Eigen::Vector3f& p3 = cloud.unfiltered[i];
        const Eigen::Vector2d q = p3.head<2>().cast<double>() - box.center_m;
        const double u = a.dot(q), v = b.dot(q), z = p3.z();
        const std::size_t view = i < cloud.unfiltered_view.size()
                                     ? std::min<std::size_t>(cloud.unfiltered_view[i], nv - 1)
                                     : 0;
        // Offset outside each face, and the face's own coordinates of the point.
        const std::array<double, 5> s = {u - hl, -u - hl, v - hw, -v - hw, z - h};
        const std::array<double, 5> ca = {v, -v, -u, u, u};
        const std::array<double, 5> cb = {z, z, z, z, v};
        for (std::size_t f = 0; f < 5; ++f) {
            if (s[f] < -inward || s[f] > config.outward_band_m) continue;
            CellStats* c = grids[f].At(ca[f], cb[f]);
            if (c == nullptr) continue;
            const auto cell = static_cast<std::size_t>(c - grids[f].cells.data());
            faces[f].cell_view[cell * static_cast<std::size_t>(nv) + view].Add(s[f]);
            if (s[f] <= inward) faces[f].view_plane[view].Add(s[f]);
        }
    }
    std::array<FaceResult, 5> out;
    for (std::size_t f = 0; f < 5; ++f) {
        out[f] = faces[f].Evaluate(config, std::max(box.face_sigma_m, 0.0005), box.face_sigma_m);
    }
    return out;
}

}  // namespace boxd::envelope
