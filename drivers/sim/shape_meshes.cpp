// The synthetic station's shapes that hide their widest part or highest point (shape_meshes.h).
#include "drivers/sim/shape_meshes.h"

#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>
#include <vector>

namespace boxd {

namespace {

// Returns the rings of a loft from t = 0 to 1 (`count` + 1 of them, at heights `length` t), each
// of half extents `a`, `b` times profile(t).
template <typename Profile>
std::vector<LoftRing> Rings(double length, double a, double b, int count, const Profile& profile) {
    std::vector<LoftRing> rings;
    for (int i = 0; i <= count; ++i) {
        const double t = static_cast<double>(i) / count, s = profile(t);
        rings.push_back({length * t, a * s, b * s});
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
    return MakeLoftMesh(Rings(h, l / 2.0, w / 2.0, 120, profile), 3.0);
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
