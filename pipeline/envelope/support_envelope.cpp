#include "pipeline/envelope/support_envelope.h"

#include <spdlog/fmt/fmt.h>
#include <spdlog/spdlog.h>

#include <algorithm>
#include <cmath>
#include <optional>
#include <utility>

#include "pipeline/core/parallel_for.h"
#include "pipeline/envelope/alike_rectangles.h"
#include "pipeline/envelope/foot_band.h"
#include "pipeline/envelope/foot_free_space.h"
#include "pipeline/envelope/layer_marks.h"
#include "pipeline/envelope/peak_reach.h"
#include "pipeline/envelope/sloped_layers.h"
#include "pipeline/envelope/surface_cells.h"
#include "pipeline/envelope/view_share.h"

namespace boxd::envelope {

namespace {

// A side's support that falls short of the readings' reach that way by more than this share
// of the object's extent across was never faced by a view: a seen side stands within the
// noise of that reach, an unseen one far inside it, where the other sides' ends and the far
// side's inside stop. Across the accuracy suite's objects the seen sides fell short by 0.8% (a
// bag) to 3.9% (a lying tube's curve) of the extent, the unseen side of a box turned through
// 140 degrees by 28% (24% under another registration tried): a quarter left that to chance.
constexpr double kUnseenShare = 0.1;

// The outer layer's largest bound in direction (cos φ, sin φ) and in the opposite one, over
// cells of (position across the direction, height).
struct Support {
    SideReach forward, backward;
    double Width() const { return forward.reach + backward.reach; }
    // The sides' noise apart, what nothing read on them together (SideReach).
    double WidthSe() const {
        return std::hypot(forward.se, backward.se, forward.unseen + backward.unseen);
    }
};

// The outer layers of several grids (cells of `sizes`: along, up), each reading projected once:
// the layers within config.layer_sigmas sigma of their cells' extremes, and a sloped surface's
// where that leaves a cell too few readings (sloped_layers.h). `tzs` gets each reading's
// (across, up, along).
std::vector<Layers> BuildLayers(const std::vector<Eigen::Vector3f>& pts, const Eigen::Vector2d& u,
                                double sigma, double radius, double top,
                                const std::vector<std::pair<double, double>>& sizes,
                                const EnvelopeConfig& config, std::vector<Eigen::Vector3d>& tzs) {
    const Eigen::Vector2d v(-u.y(), u.x());
    const std::size_t grids = sizes.size();
    std::vector<Layers> out;
    for (const auto& [along, up] : sizes) {
        out.push_back({CellGrid<LayerCell>(-radius, radius, 0.0, top, along, up),
                       CellGrid<LayerCell>(-radius, radius, 0.0, top, along, up)});
    }
    // Each reading's (across, up, along), and its cell in each grid (-1: outside it).
    tzs.resize(pts.size());
    std::vector<long> cell(pts.size() * grids, -1);
    for (std::size_t i = 0; i < pts.size(); ++i) {
        const Eigen::Vector2d q = pts[i].head<2>().cast<double>();
        tzs[i] = {v.dot(q), pts[i].z(), u.dot(q)};
        for (std::size_t g = 0; g < grids; ++g) {
            CellGrid<LayerCell>& front = out[g].front;
            if (const LayerCell* c = front.At(tzs[i].x(), tzs[i].y())) {
                cell[i * grids + g] = static_cast<long>(c - front.cells.data());
            }
        }
    }
    for (std::size_t g = 0; g < grids; ++g) {
        FillSlopedCells(CutLevelLayers(tzs, cell, grids, g, sigma, config, out[g]), sigma, config,
                        out[g]);
    }
    return out;
}

// Leaves out of `coarse` (cells twice the size each way, on the same origin) every cell that
// holds a judged cell of `fine`: there the small cells have had their say.
void KeepGapsOnly(const CellGrid<LayerCell>& fine, CellGrid<LayerCell>& coarse,
                  const EnvelopeConfig& config) {
    for (int j = 0; j < fine.nb; ++j) {
        for (int i = 0; i < fine.na; ++i) {
            const LayerCell& f = fine.cells[static_cast<std::size_t>(j) * fine.na + i];
            if (f.n < config.min_cell_points) continue;
            if (LayerCell* c = coarse.CellAt(i / 2, j / 2)) *c = LayerCell{};
        }
    }
}

// The support at the configured cells and, where they judge nothing, at cells twice as large
// each way. Where the cloud is sparse (a large object, a face seen obliquely, the subsample) a
// face's small cells may hold too few readings to be judged at all, and the support would
// silently fall back to whatever is dense inside it (a thin panel's two sides, millimetres
// apart, share their cells) — a confident footprint far too small. The larger cells hold four
// times the readings, and fill those gaps only, as faces: where a small cell is judged its
// reading stands, and a gap's larger cell is read at its mean (a larger cell's layer mixes more
// surface, and on a noisy cloud would pass the ends of the faces that meet in it for walls
// reaching millimetres farther). A small cell where the surface slopes away inward, and goes on
// sloping in the next cell (an opened panel rising from its hinge), is read at its outer end.
// Rows half as tall compete too: what stands out over less than a row's height (an opened
// panel's corner at its hinge, 2-3 mm out over a millimetre or two of height) shares its row
// with the side below it, which holds most of the readings and takes the layer's mean; half a
// row holds it apart. Their cells hold half the readings, and the noise correction and their
// standard errors count that. The configured cells read a smooth cap across them (a bag's end,
// LargestBound's `caps`); the half rows only catch what stands out of a row, and the largest of
// two noisy readings of one crest would stand above it.
Support SupportAlong(const std::vector<Eigen::Vector3f>& pts, double phi, double sigma,
                     double radius, double top, const EnvelopeConfig& config,
                     const TableBeside* table) {
    const Eigen::Vector2d u(std::cos(phi), std::sin(phi));
    const double along = config.cell_along_m, height = config.cell_height_m;
    std::vector<Eigen::Vector3d> tzs;
    std::vector<Layers> layers = BuildLayers(
        pts, u, sigma, radius, top,
        {{along, height}, {2.0 * along, 2.0 * height}, {along, height / 2.0}}, config, tzs);
    Layers &fine = layers[0], &coarse = layers[1], &thin = layers[2];
    for (Layers* l : {&fine, &thin}) {
        MarkSlopesToReadHigh(&l->front, sigma, config);
        MarkSlopesToReadHigh(&l->back, sigma, config);
    }
    KeepGapsOnly(fine.front, coarse.front, config);
    KeepGapsOnly(fine.back, coarse.back, config);
    Support out;
    int judged = 0;
    auto farther = [&](const Layers& layers, double extent, bool forward, bool walls, bool caps) {
        double se = 0.0;
        const auto& cells = forward ? layers.front.cells : layers.back.cells;
        const double bound =
            LargestBound(cells, config, sigma, sigma, extent, &se, &judged, walls, caps);
        SideReach& side = forward ? out.forward : out.backward;
        if (bound > side.reach) {
            side.reach = bound;
            side.se = se;
        }
    };
    for (bool forward : {true, false}) {
        farther(fine, std::max(along, height), forward, true, true);
        farther(coarse, 2.0 * std::max(along, height), forward, false, false);
        farther(thin, std::max(along, height / 2.0), forward, true, false);
        ReachBelow(ExtrapolateFoot(forward ? fine.front : fine.back,
                                   WallReadings{tzs, forward ? 1.0 : -1.0}, sigma, config),
                   pts, forward ? u : Eigen::Vector2d(-u), table,
                   forward ? out.forward : out.backward);
    }
    return out;
}

// An unseen side leaves the object unbounded there: a bulge or a flap could stand out
// anywhere on it, and every rectangle would be a guess. Returns the refusal where a direction's
// width `w` is unbounded, saying whether no view faced it (`unfaced`; or no camera is known).
std::optional<Error> UnboundedRefusal(const std::vector<double>& w,
                                      const std::vector<char>& unfaced, bool no_cameras) {
    const auto unbounded =
        std::count_if(w.begin(), w.end(), [](double x) { return !std::isfinite(x); });
    if (unbounded == 0) return std::nullopt;
    if (no_cameras || std::count(unfaced.begin(), unfaced.end(), 1) > 0) {
        return Error{ErrorCode::kInsufficientData,
                     "a side of the object was never seen: too few views around it to bound it"};
    }
    return Error{ErrorCode::kInsufficientData,
                 fmt::format("the object's outline cannot be bounded: in {} of {} directions, each "
                             "faced by a view, its surface stops well short of its own "
                             "readings (a part too thin or too sparse to read)",
                             unbounded, w.size())};
}

// The least-area rectangle: its two directions' supports, its direction and area.
struct LeastRectangle {
    Support su, sv;
    double phi = 0.0, area = INFINITY;
};

// The enclosing cuboid of the least rectangle `r` (the `alike` rectangles' sides where several
// are alike) and the top's height; refused where a side was never seen or its foot is
// open (foot_free_space.h).
Result<EnclosingCuboid> CuboidOf(const Surface& surface, const LeastRectangle& r,
                                 const Alike& alike, double sigma, double height_sigma,
                                 const EnvelopeConfig& config) {
    const Support &su = r.su, &sv = r.sv;
    if (!std::isfinite(r.area)) {
        return Error{ErrorCode::kInsufficientData,
                     "a side of the object was never seen: too few views around it to bound it"};
    }
    if (su.forward.open || su.backward.open || sv.forward.open || sv.backward.open) {
        return FootUnreadRefusal();
    }
    EnclosingCuboid c;
    const Eigen::Vector2d u(std::cos(r.phi), std::sin(r.phi)), v(-u.y(), u.x());
    const bool averaged = alike.orientations > 1;
    const double lu = averaged ? alike.along_u : su.Width();
    const double lv = averaged ? alike.along_v : sv.Width();
    c.center_m = 0.5 * (su.forward.reach - su.backward.reach) * u +
                 0.5 * (sv.forward.reach - sv.backward.reach) * v;
    c.length_m = std::max(lu, lv);
    c.width_m = std::min(lu, lv);
    // The sides' own direction, where the alike rectangles' sides were read turned from the least.
    const double phi = r.phi + (averaged ? alike.turn : 0.0);
    const Eigen::Vector2d axis(std::cos(phi), std::sin(phi));
    spdlog::debug(
        "envelope: least rectangle at {:.2f} deg, {:.2f} x {:.2f} mm (se {:.2f} {:.2f}); {} alike, "
        "read {:.2f} deg from it: {:.2f} x {:.2f} mm",
        r.phi * 180.0 / M_PI, su.Width() * 1e3, sv.Width() * 1e3, su.WidthSe() * 1e3,
        sv.WidthSe() * 1e3, alike.orientations, alike.turn * 180.0 / M_PI, lu * 1e3, lv * 1e3);
    c.length_axis = lu >= lv ? axis : Eigen::Vector2d(-axis.y(), axis.x());
    double se_top = 0.0;
    c.height_m = TopBound(surface.points, sigma, height_sigma, surface.radius, config, &se_top,
                          surface.view);
    ReadSharpTop(surface, height_sigma, config, &c.height_m, &se_top);
    const double s_u = averaged ? std::max(su.WidthSe(), alike.se_u) : su.WidthSe();
    const double s_v = averaged ? std::max(sv.WidthSe(), alike.se_v) : sv.WidthSe();
    c.sigma_m = {lu >= lv ? s_u : s_v, lu >= lv ? s_v : s_u, se_top};
    return c;
}

}  // namespace

double TopBound(const std::vector<Eigen::Vector3f>& pts, double sigma, double height_sigma,
                double radius, const EnvelopeConfig& config, double* se,
                const std::vector<std::uint16_t>& views) {
    const double cell = 2.0 * config.cell_along_m;
    CellGrid<LayerCell> grid(-radius, radius, -radius, radius, cell, cell);
    const int view_count = views.size() == pts.size() && !views.empty()
                               ? 1 + static_cast<int>(*std::max_element(views.begin(), views.end()))
                               : 0;
    CellViewSums by_view(view_count > 0 ? grid.cells.size() : 0, view_count);
    std::vector<double> max_z(grid.cells.size(), -INFINITY);
    for (const Eigen::Vector3f& p : pts) {
        if (LayerCell* c = grid.At(p.x(), p.y())) {
            const auto k = static_cast<std::size_t>(c - grid.cells.data());
            max_z[k] = std::max(max_z[k], static_cast<double>(p.z()));
        }
    }
    for (std::size_t i = 0; i < pts.size(); ++i) {
        const Eigen::Vector3f& p = pts[i];
        LayerCell* c = grid.At(p.x(), p.y());
        if (c == nullptr) continue;
        const auto k = static_cast<std::size_t>(c - grid.cells.data());
        if (p.z() < max_z[k] - config.layer_sigmas * sigma) continue;
        c->Add3(p.x(), p.y(), p.z());
        if (view_count > 0) by_view.Add(k, views[i], p.x(), p.y(), p.z());
    }
    MarkSlopesToReadHigh(&grid, sigma, config);
    MarkCapTops(&grid, sigma, config);
    MarkRidgesToReadHigh(&grid, config);
    // Each cell's mean as well as what its views share lets it be known (view_share.h).
    int judged = 0;
    return LargestBound(grid.cells, config, sigma, height_sigma, cell, se, &judged, true, true,
                        view_count > 0 ? &by_view : nullptr);
}

FootReach FootAlong(const Surface& surface, const Eigen::Vector2d& u, double sigma,
                    const EnvelopeConfig& config) {
    std::vector<Eigen::Vector3d> tzs;
    std::vector<Layers> layers =
        BuildLayers(surface.points, u, sigma, surface.radius, surface.top,
                    {{config.cell_along_m, config.cell_height_m}}, config, tzs);
    MarkSlopesToReadHigh(&layers[0].front, sigma, config);
    return ExtrapolateFoot(layers[0].front, WallReadings{tzs}, sigma, config);
}

Result<EnclosingCuboid> EnvelopeCuboid(const Surface& surface, double sigma, double height_sigma,
                                       const EnvelopeConfig& config) {
    const std::vector<Eigen::Vector3f>& pts = surface.points;
    if (pts.empty()) return Error{ErrorCode::kInsufficientData, "no surface above the table"};
    const double radius = surface.radius, top = surface.top;
    const TableBeside table = TableBesideOf(surface, sigma, config);
    const TableBeside* beside = surface.table_known ? &table : nullptr;
    // A side no view faced has no facing surface: its "support" would be whatever faces that
    // way farther in (the far side's inside, a panel's back), well inside the readings of the
    // top or the other sides that reach out there. Such a direction bounds nothing. Where a view
    // did face the direction, the surface stopping short of the readings is a part too thin or
    // too sparse to read (a parcel sweep's flat carton with a flap, 12 views round it, fell 73 mm
    // short at two directions by a corner; left out, the rest read its length 1.1 mm short with a
    // 0.35 mm bound): the object is refused all the same, saying which.
    Eigen::Vector3d middle(0.0, 0.0, top / 2.0);
    for (const Eigen::Vector3f& p : pts) middle.head<2>() += p.head<2>().cast<double>();
    middle.head<2>() /= static_cast<double>(pts.size());
    const double faced_cos = std::cos(config.max_incidence_deg * M_PI / 180.0);
    auto faced = [&](const Eigen::Vector2d& u) {
        return std::any_of(
            surface.cameras.begin(), surface.cameras.end(), [&](const Eigen::Vector3f& camera) {
                const Eigen::Vector3d ray = (camera.cast<double>() - middle).normalized();
                return u.dot(ray.head<2>()) >= faced_cos;
            });
    };
    auto width = [&](double phi, Support* s, char* unseen) -> double {
        *s = SupportAlong(pts, phi, sigma, radius, top, config, beside);
        const Eigen::Vector2f u(static_cast<float>(std::cos(phi)),
                                static_cast<float>(std::sin(phi)));
        double reach_f = -INFINITY, reach_b = -INFINITY;
        for (const Eigen::Vector3f& p : pts) {
            const double d = u.dot(p.head<2>());
            reach_f = std::max(reach_f, d);
            reach_b = std::max(reach_b, -d);
        }
        const double slack = kUnseenShare * (reach_f + reach_b);
        const bool short_f = s->forward.reach < reach_f - slack,
                   short_b = s->backward.reach < reach_b - slack;
        if (!short_f && !short_b) return s->Width();
        const Eigen::Vector2d ud(std::cos(phi), std::sin(phi));
        if (unseen && ((short_f && !faced(ud)) || (short_b && !faced(-ud)))) *unseen = 1;
        return INFINITY;
    };
    // Every direction, then finer about the least area.
    const int n = config.directions;
    std::vector<Support> coarse(static_cast<std::size_t>(n));
    std::vector<double> w(static_cast<std::size_t>(n));
    std::vector<char> unfaced(static_cast<std::size_t>(n), 0);  // short where no view faced
    ParallelFor(n, config.threads, [&](int i) {
        w[i] = width(M_PI * i / n, &coarse[i], &unfaced[static_cast<std::size_t>(i)]);
    });
    if (auto why = UnboundedRefusal(w, unfaced, surface.cameras.empty())) return *why;
    int best = 0;
    for (int i = 1; i < n; ++i) {
        if (w[i] * w[(i + n / 2) % n] < w[best] * w[(best + n / 2) % n]) best = i;
    }
    LeastRectangle r{coarse[best], coarse[(best + n / 2) % n], M_PI * best / n,
                     w[best] * w[(best + n / 2) % n]};
    std::vector<double> w_se(static_cast<std::size_t>(n));
    for (int i = 0; i < n; ++i) w_se[i] = coarse[i].WidthSe();
    const auto alike = AlikeRectangles(w, w_se, best);
    if (alike.orientations == 1) {
        // Tenths of a step either way, each direction and the one square to it.
        constexpr int kFine = 9;
        std::vector<Support> fine(4 * kFine + 2);
        std::vector<double> fine_w(fine.size());
        auto phi_of = [&](int k) {
            return M_PI * best / n + (k / 2 - kFine) * (M_PI / n) / 10.0 + (k % 2) * M_PI / 2.0;
        };
        ParallelFor(static_cast<int>(fine.size()), config.threads,
                    [&](int k) { fine_w[k] = width(phi_of(k), &fine[k], nullptr); });
        for (std::size_t k = 0; k < fine.size(); k += 2) {
            const double area = fine_w[k] * fine_w[k + 1];
            if (area < r.area) r = {fine[k], fine[k + 1], phi_of(static_cast<int>(k)), area};
        }
    }
    return CuboidOf(surface, r, alike, sigma, height_sigma, config);
}

}  // namespace boxd::envelope
