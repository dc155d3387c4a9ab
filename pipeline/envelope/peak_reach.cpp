#include "pipeline/envelope/peak_reach.h"

#include <spdlog/spdlog.h>

#include <Eigen/Eigenvalues>
#include <algorithm>
#include <functional>
#include <map>
#include <numeric>
#include <optional>

#include "pipeline/core/median.h"
#include "pipeline/core/student_t.h"
#include "pipeline/envelope/surface_cells.h"

namespace boxd::envelope {

namespace {

// The highest readings, whose mean is the apex point; the third highest is the height they hold.
constexpr std::size_t kApexReadings = 5;
// A top whose readings spread this many times farther one way than the other is a ridge.
constexpr double kRidgeElongation = 4.0;
// The readings of a view whose nearest neighbours give its spacing (an even sample).
constexpr std::size_t kSpacingSamples = 200;
// The top's readings in bins of drop, each needing this many to count.
constexpr int kDropBins = 6;
constexpr std::size_t kBinReadings = 5;
// Flanks steeper than this (84 degrees) are walls: the top is their edge, read as it stands.
constexpr double kMaxSlope = 10.0;
// A point's flanks are read in this many sectors round it (a pyramid's four faces and the
// edges between them), the steepest setting how high the apex may stand.
constexpr int kFlankSectors = 8;
constexpr std::size_t kFlankReadings = 20;  // a flank's plane needs this many readings

// The median over views of the median distance from a reading of the top to the nearest other
// reading of the same view (all readings as one view where `view` is empty): how finely a view
// samples the surface across its rays there (on a steep flank the readings stack nearly
// straight up, their horizontal spacing a fraction of it).
double ViewSpacing(const std::vector<Eigen::Vector3f>& top,
                   const std::vector<std::uint16_t>& view) {
    std::map<int, std::vector<Eigen::Vector3f>> by_view;
    for (std::size_t i = 0; i < top.size(); ++i) {
        by_view[view.empty() ? 0 : view[i]].push_back(top[i]);
    }
    std::vector<double> spacings;
    for (const auto& [v, q] : by_view) {
        if (q.size() < 3) continue;
        std::vector<double> nearest;
        // At most kSpacingSamples readings a view are asked for their nearest neighbour.
        const std::size_t step = std::max<std::size_t>(1, q.size() / kSpacingSamples);
        for (std::size_t i = 0; i < q.size(); i += step) {
            double best = INFINITY;
            for (std::size_t j = 0; j < q.size(); ++j) {
                if (j != i) best = std::min(best, static_cast<double>((q[i] - q[j]).norm()));
            }
            nearest.push_back(best);
        }
        spacings.push_back(Median(nearest));
    }
    return spacings.empty() ? 0.0 : Median(spacings);
}

// How far `p` lies from the apex point `apex`, or across the ridge line through it where
// `across` (the unit vector across the ridge) is given.
double Away(const Eigen::Vector3f& p, const Eigen::Vector2d& apex, const Eigen::Vector2d* across) {
    const Eigen::Vector2d q = p.head<2>().cast<double>() - apex;
    return across ? std::abs(across->dot(q)) : q.norm();
}

// The median drop below `highest` of the top's readings within `reach` of the apex point (or
// across the ridge line); infinite for fewer than kFlankReadings of them (it cannot tell).
double MedianDrop(const std::vector<Eigen::Vector3f>& top, const Eigen::Vector2d& apex,
                  const Eigen::Vector2d* across, double highest, double reach) {
    std::vector<double> drops;
    for (const Eigen::Vector3f& p : top) {
        if (Away(p, apex, across) < reach) drops.push_back(highest - p.z());
    }
    return drops.size() < kFlankReadings ? INFINITY : Median(std::move(drops));
}

// The top's readings in kDropBins bins of their drop below `highest`: each bin's mid drop, its
// readings' median distance from the apex point (or across the ridge line) and that median's
// standard error (the interquartile range's sigma, 1.2533 sigma / sqrt(n) for a median).
struct DropBins {
    std::vector<double> x, y, se;
};

DropBins BinByDrop(const std::vector<Eigen::Vector3f>& top, const Eigen::Vector2d& apex,
                   const Eigen::Vector2d* across, double highest, double band_m,
                   double noise_sigma) {
    std::vector<std::vector<double>> bins(kDropBins);
    for (const Eigen::Vector3f& p : top) {
        const int bin = static_cast<int>((highest - p.z()) / band_m * kDropBins);
        if (bin < 0 || bin >= kDropBins) continue;
        bins[static_cast<std::size_t>(bin)].push_back(Away(p, apex, across));
    }
    DropBins out;
    for (int b = 0; b < kDropBins; ++b) {
        const std::vector<double>& d = bins[static_cast<std::size_t>(b)];
        // Within twice the noise of the highest, a reading's drop is its noise's more than
        // the surface's: the readings of a bin there were read from every depth down to
        // twice as far, and their distances tell no shape.
        if (d.size() < kBinReadings || (b + 0.5) * band_m / kDropBins < 2.0 * noise_sigma) {
            continue;
        }
        const double sigma = (Quantile(d, 0.75) - Quantile(d, 0.25)) / 1.349;
        out.x.push_back((b + 0.5) * band_m / kDropBins);
        out.y.push_back(Median(d));
        out.se.push_back(1.2533 * sigma / std::sqrt(static_cast<double>(d.size())));
    }
    return out;
}

// The flanks' slope from how the top widens going down: a line through the bins' (drop,
// distance) by least squares: a flank rising s metres per metre runs 1/s metre out per metre
// down. A top already `narrow_m` wide where it is highest (a face), one that does not widen (a
// panel's edge, its width its thickness), widens as a smooth crown does, or is flat where it is
// highest (its readings there within `noise_sigma`, a reading's noise in its height, of the
// highest), has none.
std::optional<double> FlankSlope(const std::vector<Eigen::Vector3f>& top,
                                 const Eigen::Vector2d& apex, const Eigen::Vector2d* across,
                                 double highest, double band_m, double narrow_m,
                                 double noise_sigma) {
    const DropBins bins = BinByDrop(top, apex, across, highest, band_m, noise_sigma);
    const std::vector<double>&x = bins.x, &y = bins.y;
    const double n = static_cast<double>(x.size());
    double sx = 0.0, sy = 0.0, sxx = 0.0, sxy = 0.0, sqx = 0.0, sqy = 0.0;
    for (std::size_t i = 0; i < x.size(); ++i) {
        sx += x[i];
        sy += y[i];
        sxx += x[i] * x[i];
        sxy += x[i] * y[i];
        sqx += x[i];  // sqrt(x)^2
        sqy += std::sqrt(x[i]) * y[i];
    }
    const double det = n * sxx - sx * sx;
    if (n < 3.0 || !(det > 0.0)) return std::nullopt;
    const double run = (n * sxy - sx * sy) / det;  // metres out per metre down
    const double at_top = (sy - run * sx) / n;
    // A smooth crown widens as the root of the drop (a radius of curvature r: d = sqrt(2 r drop)),
    // a flank in proportion to it: the crown's model fitting better, and the line missing the
    // bins beyond their errors, it is no sharp top. Where the line is within them, the top may be
    // a point: near a steep apex that no reading reached the noise smears the readings outwards,
    // and a pyramid's top widens as the root of the drop too (a stereo camera's, its apex 10 mm
    // above its highest readings, was read as a crown 9.8 mm low within a 2.0 mm bound).
    const double root = sqy / sqx;
    double line_rss = 0.0, root_rss = 0.0, line_chi2 = 0.0;
    for (std::size_t i = 0; i < x.size(); ++i) {
        const double miss = y[i] - at_top - run * x[i];
        line_rss += miss * miss;
        root_rss += std::pow(y[i] - root * std::sqrt(x[i]), 2);
        line_chi2 += bins.se[i] > 0.0 ? std::pow(miss / bins.se[i], 2) : INFINITY;
    }
    if (!(line_rss < root_rss) &&
        line_chi2 > UpperChiSquareQuantile(0.05, static_cast<int>(n) - 2)) {
        return std::nullopt;
    }
    // A top as wide as a cell where it is highest is a face, not a point or a line.
    if (!(at_top <= narrow_m)) return std::nullopt;
    // However gently the flanks rise, a point is no crown: the top's cells read it at a cell's
    // mean, below the apex by a share of the slope times the cell, which a crown's curvature
    // marks up (MarkCapTops) and a cone's does not: pyramids 71 and 83 mm tall, their flanks
    // rising about half a metre per metre, read 2.6 and 2.2 mm low against bounds of 2.8 and
    // 1.6 mm, and as points 1.5 and 1.4 mm low within 2.1 and 1.8 mm. How the top widens tells
    // the two apart, not how steeply.
    if (!(run > 0.0) || 1.0 / run > kMaxSlope) return std::nullopt;
    // A sharp top is a point or a line: the readings nearest it, within half the distance at
    // which the flanks would hold the band's lowest readings, lie mostly on the flanks below it
    // (a pyramid's, smeared along their rays, a median 10 mm below the highest). A top flat where
    // it is highest, whose readings widen only below it (a strap's bar 25 mm wide, the mixed
    // pixels along its edges), keeps them at its height, within a reading's noise (the bar's
    // 0.1-0.8 of it): its top is read, and no apex stands above it (a handle read 8 mm tall
    // within an 8 mm bound). Beyond one noise and within two, the noise cannot tell a flat top
    // from a point's flanks: read as a point, whose bound reaches down to its highest readings
    // where a flat top would stand (a stereo camera's steep prism, its ridge's nearest readings
    // 1.7 noises below its highest, read as flat 3.9 mm low within a 1.3 mm bound).
    if (!(MedianDrop(top, apex, across, highest, (at_top + run * band_m) / 2.0) > noise_sigma)) {
        return std::nullopt;
    }
    return 1.0 / run;
}

// The slope (rise per metre) of the plane fitted to `flank`'s readings, the steepest way up
// it; none for fewer than kFlankReadings readings or a plane standing upright. The plane is the
// readings' least-variance axis, not a fit of their heights: a reading's noise lies along its
// ray, across the flank as much as up it, and heights fitted against noisy places read a flank
// gentler than it is (a pyramid's 1.61 face read 1.48 by a stereo camera 1.1 m away).
std::optional<double> PlaneSlope(const std::vector<Eigen::Vector3f>& flank) {
    if (flank.size() < kFlankReadings) return std::nullopt;
    LayerCell cell;  // its (across, up, along) here (x, y, z)
    for (const Eigen::Vector3f& p : flank) cell.Add3(p.x(), p.y(), p.z());
    const Eigen::Vector3d normal = cell.Normal();
    if (!(std::abs(normal.z()) > 0.0)) return std::nullopt;
    return normal.head<2>().norm() / std::abs(normal.z());
}

// The steepest of a point's flanks, at least `slope` (theirs together, FlankSlope): the plane
// of each of kFlankSectors sectors round it (a pyramid's faces, and the edges between them,
// which fit gentler). A face's plane gives its own slope whichever way across it the readings
// lie; their median run together (FlankSlope's) reads a pyramid's steeper faces up to half as
// steep, and the apex then stands higher above the readings than the reach allowed.
double SteepestFlank(const std::vector<Eigen::Vector3f>& top, const Eigen::Vector2d& apex,
                     double slope) {
    std::vector<std::vector<Eigen::Vector3f>> flanks(kFlankSectors);
    for (const Eigen::Vector3f& p : top) {
        const Eigen::Vector2d q = p.head<2>().cast<double>() - apex;
        const double turn = (std::atan2(q.y(), q.x()) + M_PI) / (2.0 * M_PI);
        const int k = std::min(kFlankSectors - 1, static_cast<int>(turn * kFlankSectors));
        flanks[static_cast<std::size_t>(k)].push_back(p);
    }
    double steepest = slope;
    for (const auto& flank : flanks) {
        const auto s = PlaneSlope(flank);
        if (s) steepest = std::max(steepest, std::min(*s, kMaxSlope));
    }
    return steepest;
}

// The third highest of the heights of `pts`, each less its `raised` where given (the two highest
// may be strays), less the median of the largest of as many noise draws as readings compete for
// it (a ridge's hundreds stand 3 sigma out).
double HighestReadings(const std::vector<Eigen::Vector3f>& pts, const std::vector<float>& raised,
                       double noise_sigma) {
    std::vector<double> z(pts.size());
    for (std::size_t i = 0; i < pts.size(); ++i) {
        z[i] = pts[i].z() - (i < raised.size() ? raised[i] : 0.0f);
    }
    std::nth_element(z.begin(), z.begin() + 2, z.end(), std::greater<>());
    const double third = z[2];
    const auto competing =
        std::count_if(z.begin(), z.end(), [&](double h) { return h >= third - 2.0 * noise_sigma; });
    return third - noise_sigma * MedianOfLargest(std::max<int>(1, static_cast<int>(competing)));
}

}  // namespace

PeakReach ExtrapolatePeak(const std::vector<Eigen::Vector3f>& pts,
                          const std::vector<std::uint16_t>& view, const std::vector<float>& raised,
                          double noise_sigma, double band_m, double narrow_m, double narrowest_m) {
    PeakReach out;
    if (pts.size() < 20) return out;
    std::vector<std::size_t> order(pts.size());
    std::iota(order.begin(), order.end(), 0);
    std::partial_sort(order.begin(), order.begin() + kApexReadings, order.end(),
                      [&](std::size_t a, std::size_t b) { return pts[a].z() > pts[b].z(); });
    // The top's shape is read from the readings as corrected; the height they hold, from them
    // as read.
    const double reference = HighestReadings(pts, {}, noise_sigma);
    out.highest = raised.empty() ? reference : HighestReadings(pts, raised, noise_sigma);
    Eigen::Vector2d apex = Eigen::Vector2d::Zero();
    for (std::size_t i = 0; i < kApexReadings; ++i) {
        apex += pts[order[i]].head<2>().cast<double>() / static_cast<double>(kApexReadings);
    }
    std::vector<Eigen::Vector3f> top;
    std::vector<std::uint16_t> top_view;
    for (std::size_t i = 0; i < pts.size(); ++i) {
        if (pts[i].z() < reference - band_m) continue;
        top.push_back(pts[i]);
        if (i < view.size()) top_view.push_back(view[i]);
    }
    if (top.size() < 20) return out;
    if (top_view.size() != top.size()) top_view.clear();
    // A ridge when the top runs along one line: distances are then taken across it.
    Eigen::Matrix2d cov = Eigen::Matrix2d::Zero();
    for (const Eigen::Vector3f& p : top) {
        const Eigen::Vector2d q = p.head<2>().cast<double>() - apex;
        cov += q * q.transpose() / static_cast<double>(top.size());
    }
    const Eigen::SelfAdjointEigenSolver<Eigen::Matrix2d> eig(cov);
    const bool ridge = eig.eigenvalues()(1) > kRidgeElongation * eig.eigenvalues()(0);
    const Eigen::Vector2d across = eig.eigenvectors().col(0);
    const auto slope =
        FlankSlope(top, apex, ridge ? &across : nullptr, reference, band_m, narrow_m, noise_sigma);
    if (!slope) return out;
    // The apex may stand above the readings by its steepest flank's rise over the farthest it
    // may lie from the nearest: across a ridge, half the readings' spacing; a point among
    // readings spread both ways, half the diagonal of their spacing. Or over half the narrowest
    // width the fusion keeps, where that is wider.
    out.slope = ridge ? *slope : SteepestFlank(top, apex, *slope);
    out.spacing = ViewSpacing(top, top_view);
    const double farthest = ridge ? out.spacing / 2.0 : out.spacing / std::sqrt(2.0);
    out.above = out.slope * std::max(farthest, narrowest_m / 2.0);
    out.sharp = true;
    return out;
}

void ReadSharpTop(const Surface& surface, double height_sigma, const EnvelopeConfig& config,
                  double* height, double* se) {
    const PeakReach peak =
        ExtrapolatePeak(surface.points, surface.view, surface.raised, height_sigma,
                        2.0 * config.cell_height_m, config.cell_along_m, config.narrowest_kept_m);
    if (!peak.sharp) {
        // Its highest readings still hold the height from below where they stand above the
        // cells beyond their noise: a top too thin for any cell, its flanks steeper than any
        // (a narrow pyramid's last centimetres read as a fin's edge, 28 mm above its cells).
        if (peak.highest > *height + 2.0 * height_sigma) {
            *height = peak.highest;
            *se = std::max(*se, height_sigma);
        }
        return;
    }
    spdlog::debug(
        "envelope: a sharp top, its highest readings {:.2f} mm above the cells', slope "
        "{:.2f}, spacing {:.2f} mm",
        (peak.highest - *height) * 1e3, peak.slope, peak.spacing * 1e3);
    if (peak.highest > *height) {
        *height = peak.highest;
        *se = height_sigma;
    }
    *height += peak.above / 2.0;
    *se = std::hypot(*se, peak.above / 2.0 / kNormal95);
}

}  // namespace boxd::envelope
