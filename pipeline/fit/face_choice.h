#pragma once
// Fit stage: which readings a face fit takes (box_fit.h): a face's margins read where a reading's
// ray meets the face's plane.

#include <Eigen/Core>
#include <algorithm>
#include <cmath>
#include <cstdint>
#include <optional>
#include <vector>

namespace boxd {

// Where a fit's readings were seen from: each reading's view and each view's camera, in the
// readings' frame. A reading's noise lies along its ray; which face a reading counts for, and
// whether it lies clear of that face's edges, is read where its ray meets the face's plane.
struct ReadingRays {
    const std::vector<std::uint16_t>* view = nullptr;       // per reading
    const std::vector<Eigen::Vector3f>* cameras = nullptr;  // per view
    // True when every one of `readings` readings names a view with a camera.
    bool Covers(std::size_t readings) const;
};

// How far inside a face's edges its readings count: the configured margin (edge_margin_m, which
// keeps the blur of an edge, its rounding and the next face's readings out of a face's fit), but
// no more than a quarter of the object's smallest extent, so that every face keeps half of
// itself to be read. A 30 mm high carton's sides were otherwise all margin (15 mm at each end)
// and the carton was refused; objects of 60 mm and more in every extent keep the configured
// margin.
inline double EdgeMargin(double configured_m, double smallest_extent_m) {
    return std::min(configured_m, 0.25 * std::max(smallest_extent_m, 0.0));
}

// The same for a fitted box whose faces round off farther in than that (`rounded_m`,
// BoxFit::rounded_margin_m, rounded_edges.h; 0 where they do not): its faces are read beyond it.
inline double EdgeMargin(double configured_m, double smallest_extent_m, double rounded_m) {
    return std::max(EdgeMargin(configured_m, smallest_extent_m), rounded_m);
}

// Which readings a face fit takes. Axial noise moves a reading along its ray, so where a face is
// seen obliquely it moves the reading along the face as much as across it: a margin from the
// face's edges read at the reading's position keeps, at each end of the face, the readings their
// noise moved inwards, and with them one sign of the noise across the face, one sign at the near
// end, the other at the far end, in unequal numbers. The face moves: a tall box's top seen in one
// Kinect frame a pose read 0.055 mm low on average (8 seeds), 0.009 mm chosen by rays. Where the
// reading's ray meets the face's plane carries none of its depth's noise: the margins are read
// there. Which face a reading belongs to is still read at its position, against a third of the
// margin, well clear of the readings the margin keeps.
class FaceChoice {
public:
    FaceChoice(const ReadingRays* rays, double margin)
        : rays_(rays), margin_(margin), gate_(rays ? margin / 3.0 : margin) {}

    double margin() const { return margin_; }
    // How far inside a face's edges a reading must lie, at its position.
    double gate() const { return gate_; }
    // Where reading `i` is judged against the margin: where its ray meets the plane of unit
    // normal `normal` at offset `offset`, or the reading itself without rays; none when its ray
    // runs along the plane.
    std::optional<Eigen::Vector3d> Judged(std::size_t i, const Eigen::Vector3f& reading,
                                          const Eigen::Vector3d& normal, double offset) const {
        const Eigen::Vector3d q = reading.cast<double>();
        if (!rays_) return q;
        const Eigen::Vector3d c = (*rays_->cameras)[(*rays_->view)[i]].cast<double>();
        const double along = normal.dot(q - c);
        if (std::abs(along) < 1e-9) return std::nullopt;
        return c + (offset - normal.dot(c)) / along * (q - c);
    }

private:
    const ReadingRays* rays_;
    double margin_, gate_;
};

}  // namespace boxd
