// The synthetic station's shapes that hide their widest part or highest point (shape_meshes.h).
#include "drivers/sim/shape_meshes.h"

#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>
#include <vector>

namespace boxd {

namespace {

// Returns the rings of a loft from t = 0 to 1 (`count` + 1 of them, at heights `length` t), each
// of half extents `a`, `b` times profile(t); with `tolerance_m`, each step is halved until the
// profile's midpoint lies within it of the step's chord (the larger half extent's outline). Even
// steps leave a dome's crown, where the profile turns level, a cone: a sack 150 mm tall, 120
// rings, rose to its apex 1.3 mm over its last 27 mm, 0.3 mm under the dome halfway.
template <typename Profile>
std::vector<LoftRing> Rings(double length, double a, double b, int count, const Profile& profile,
                            double tolerance_m = 0.0) {
    constexpr int kMaxHalvings = 16;
    const double r = std::max(a, b);
    std::vector<LoftRing> rings;
    auto ring = [&](double t) { return LoftRing{length * t, a * profile(t), b * profile(t)}; };
    // Adds the rings after t0 up to t1, halving the step where the chord strays.
    auto step = [&](auto&& self, double t0, double t1, int depth) -> void {
        const double tm = 0.5 * (t0 + t1);
        const Eigen::Vector2d p0(length * t0, r * profile(t0)), p1(length * t1, r * profile(t1));
        const Eigen::Vector2d pm(length * tm, r * profile(tm)), chord = p1 - p0;
        const double off =
            chord.norm() > 0.0
                ? std::abs(chord.x() * (pm - p0).y() - chord.y() * (pm - p0).x()) / chord.norm()
                : 0.0;
        if (tolerance_m > 0.0 && depth < kMaxHalvings && off > tolerance_m) {
            self(self, t0, tm, depth + 1);
            self(self, tm, t1, depth + 1);
            return;
        }
        rings.push_back(ring(t1));
    };
    rings.push_back(ring(0.0));
    for (int i = 0; i < count; ++i) {
        step(step, static_cast<double>(i) / count, static_cast<double>(i + 1) / count, 0);
    }
    return rings;
}

}  // namespace

TriangleMesh MakeSackMesh(double l, double w, double h) {
    constexpr double kWidest = 0.3, kFoot = 0.72, kShoulder = 0.8, kUpper = 0.85;
    auto profile = [&](double t) {
        if (t <= kWidest) return kFoot + (1.0 - kFoot) * std::sin(0.5 * M_PI * t / kWidest);
        if (t <= kShoulder) {
            const double u = (t - kWidest) / (kShoulder - kWidest);
            return 1.0 - (1.0 - kUpper) * u * u;
        }
        const double u = (t - kShoulder) / (1.0 - kShoulder);
        return kUpper * std::sqrt(std::max(0.0, 1.0 - u * u));
    };
    // Its rings follow the profile to 50 micrometres, the crown a dome to its apex.
    return MakeLoftMesh(Rings(h, l / 2.0, w / 2.0, 120, profile, 5e-5), 3.0);
}

TriangleMesh MakeLyingBottleMesh(double l, double d) {
    constexpr double kBase = 0.02, kBody = 0.62, kShoulder = 0.8, kNeck = 0.35, kLip = 0.97;
    auto profile = [&](double t) {
        if (t <= kBase) return 0.9 + 0.1 * std::sin(0.5 * M_PI * t / kBase);
        if (t <= kBody) return 1.0;
        if (t <= kShoulder) {
            const double u = (t - kBody) / (kShoulder - kBody);
            return 1.0 - (1.0 - kNeck) * 0.5 * (1.0 - std::cos(M_PI * u));
        }
        return t <= kLip ? kNeck : 0.4;
    };
    const TriangleMesh along_z = MakeLoftMesh(Rings(l, d / 2.0, d / 2.0, 200, profile), 2.0);
    // Along +x, resting on the table on its side.
    const Eigen::Matrix3d to_x = Eigen::AngleAxisd(M_PI / 2.0, Eigen::Vector3d::UnitY()).matrix();
    return along_z.Transformed(to_x, {-l / 2.0, 0.0, d / 2.0});
}

TriangleMesh MakeChamferedBoxMesh(double l, double w, double h, double chamfer) {
    TriangleMesh mesh = MakeTaperedBoxMesh(l - 2.0 * chamfer, w - 2.0 * chamfer, chamfer, l, w);
    mesh.Append(MakeCuboidMesh({-l / 2.0, -w / 2.0, chamfer}, {l / 2.0, w / 2.0, h}));
    return mesh;
}

TriangleMesh MakeBoxOnBoxMesh(double l, double w, double h) {
    const double lower = 0.6 * h, upper_l = 0.55 * l, upper_w = 0.6 * w, shift = 0.2 * l;
    TriangleMesh mesh = MakeCuboidMesh({-l / 2.0, -w / 2.0, 0.0}, {l / 2.0, w / 2.0, lower});
    mesh.Append(MakeCuboidMesh({shift - upper_l / 2.0, -upper_w / 2.0, lower},
                               {shift + upper_l / 2.0, upper_w / 2.0, h}));
    return mesh;
}

TriangleMesh MakeHandleBoxMesh(double l, double w, double h) {
    constexpr double kBand = 0.025, kThickness = 0.004;
    const double loop = std::clamp(0.15 * h, 0.02, 0.05), top = h - loop, at = 0.25 * l;
    TriangleMesh mesh = MakeCuboidMesh({-l / 2.0, -w / 2.0, 0.0}, {l / 2.0, w / 2.0, top});
    for (const double x : {-at, at - kThickness}) {
        mesh.Append(MakeCuboidMesh({x, -kBand / 2.0, top}, {x + kThickness, kBand / 2.0, h}));
    }
    mesh.Append(MakeCuboidMesh({-at, -kBand / 2.0, h - kThickness}, {at, kBand / 2.0, h}));
    return mesh;
}

}  // namespace boxd
