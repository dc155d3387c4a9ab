#include "drivers/sim/triangle_mesh.h"

#include <algorithm>
#include <cmath>

namespace boxd {

namespace {

// Appends the quad grid of one face: `corner` + s * `du` + t * `dv` for s, t in [0, 1], each
// point passed through `shape`; du x dv points out of the solid.
template <typename Shape>
void AppendFaceGrid(TriangleMesh& mesh, const Eigen::Vector3d& corner, const Eigen::Vector3d& du,
                    const Eigen::Vector3d& dv, int cells, const Shape& shape) {
    const auto base = static_cast<std::uint32_t>(mesh.vertices.size());
    for (int j = 0; j <= cells; ++j) {
        for (int i = 0; i <= cells; ++i) {
            // Both parameters from integer ratios, so points on a shared edge are computed by the
            // same expression on both faces and the surface has no cracks.
            const Eigen::Vector3d p = corner + du * (static_cast<double>(i) / cells) +
                                      dv * (static_cast<double>(j) / cells);
            mesh.vertices.push_back(shape(p).template cast<float>());
        }
    }
    const auto row = static_cast<std::uint32_t>(cells + 1);
    for (int j = 0; j < cells; ++j) {
        for (int i = 0; i < cells; ++i) {
            const std::uint32_t a =
                base + static_cast<std::uint32_t>(j) * row + static_cast<std::uint32_t>(i);
            mesh.triangles.push_back({a, a + 1, a + row + 1});
            mesh.triangles.push_back({a, a + row + 1, a + row});
        }
    }
}

// Returns 1 - x^2 clamped to [0, 1]: a parabola that is 1 in the middle of [-1, 1], 0 at its ends.
double Panel(double x) { return std::max(0.0, 1.0 - x * x); }

}  // namespace

void TriangleMesh::Append(const TriangleMesh& other) {
    const auto base = static_cast<std::uint32_t>(vertices.size());
    vertices.insert(vertices.end(), other.vertices.begin(), other.vertices.end());
    for (const auto& t : other.triangles)
        triangles.push_back({t[0] + base, t[1] + base, t[2] + base});
}

TriangleMesh TriangleMesh::Transformed(const Eigen::Matrix3d& rotation,
                                       const Eigen::Vector3d& t) const {
    TriangleMesh out;
    out.triangles = triangles;
    out.vertices.reserve(vertices.size());
    for (const Eigen::Vector3f& v : vertices) {
        out.vertices.push_back((rotation * v.cast<double>() + t).cast<float>());
    }
    return out;
}

std::array<Eigen::Vector3d, 2> TriangleMesh::Bounds() const {
    Eigen::Vector3d lo = Eigen::Vector3d::Constant(1e300), hi = -lo;
    for (const Eigen::Vector3f& v : vertices) {
        lo = lo.cwiseMin(v.cast<double>());
        hi = hi.cwiseMax(v.cast<double>());
    }
    return {lo, hi};
}

TriangleMesh MakeBoxMesh(double l, double w, double h, const BoxDeformation& d, int cells) {
    const Eigen::Vector3d half(l / 2.0, w / 2.0, h / 2.0);
    const Eigen::Vector3d centre(0.0, 0.0, h / 2.0);
    const double r = std::clamp(d.edge_radius_m, 0.0, half.minCoeff());
    const Eigen::Vector3d inner = half - Eigen::Vector3d::Constant(r);
    // A point of the ideal box surface -> the rounded box (the point of the inner box nearest to
    // it, pushed out by r towards it), then the bulge of the face it belongs to along that
    // face's normal. The bottom stands flat on the table.
    auto shape = [&](const Eigen::Vector3d& p) -> Eigen::Vector3d {
        const Eigen::Vector3d q = p - centre;
        const Eigen::Vector3d core = q.cwiseMax(-inner).cwiseMin(inner);
        const Eigen::Vector3d out = q - core;
        Eigen::Vector3d s = out.norm() > 1e-12 ? core + r * out.normalized() : q;
        const Eigen::Vector3d u = q.cwiseQuotient(half);  // -1..1 on each axis
        if (std::abs(std::abs(u.x()) - 1.0) < 1e-12) {
            s.x() += std::copysign(d.side_bulge_m * Panel(u.y()) * Panel(u.z()), u.x());
        } else if (std::abs(std::abs(u.y()) - 1.0) < 1e-12) {
            s.y() += std::copysign(d.side_bulge_m * Panel(u.x()) * Panel(u.z()), u.y());
        } else if (u.z() > 1.0 - 1e-12) {
            s.z() += d.top_bulge_m * Panel(u.x()) * Panel(u.y());
        }
        return Eigen::Vector3d(s + centre);
    };
    TriangleMesh mesh;
    const double L = l, W = w, H = h;
    const Eigen::Vector3d X(L, 0, 0), Y(0, W, 0), Z(0, 0, H);
    const Eigen::Vector3d o(-l / 2.0, -w / 2.0, 0.0);  // the (-x, -y, bottom) corner
    AppendFaceGrid(mesh, o + X, Y, Z, cells, shape);   // +x
    AppendFaceGrid(mesh, o, Z, Y, cells, shape);       // -x
    AppendFaceGrid(mesh, o + Y, Z, X, cells, shape);   // +y
    AppendFaceGrid(mesh, o, X, Z, cells, shape);       // -y
    AppendFaceGrid(mesh, o + Z, X, Y, cells, shape);   // top
    AppendFaceGrid(mesh, o, Y, X, cells, shape);       // bottom
    return mesh;
}

TriangleMesh MakeCuboidMesh(const Eigen::Vector3d& lo, const Eigen::Vector3d& hi) {
    const Eigen::Vector3d e = hi - lo;
    const Eigen::Vector3d X(e.x(), 0, 0), Y(0, e.y(), 0), Z(0, 0, e.z());
    auto same = [](const Eigen::Vector3d& p) { return p; };
    TriangleMesh mesh;
    AppendFaceGrid(mesh, lo + X, Y, Z, 1, same);
    AppendFaceGrid(mesh, lo, Z, Y, 1, same);
    AppendFaceGrid(mesh, lo + Y, Z, X, 1, same);
    AppendFaceGrid(mesh, lo, X, Z, 1, same);
    AppendFaceGrid(mesh, lo + Z, X, Y, 1, same);
    AppendFaceGrid(mesh, lo, Y, X, 1, same);
    return mesh;
}

TriangleMesh MakeTaperedBoxMesh(double l, double w, double h, double top_l, double top_w,
                                double top_dx, double top_dy) {
    TriangleMesh mesh;
    // Bottom corners 0-3 and top corners 4-7, counter-clockwise seen from above.
    const double sx[4] = {-1, 1, 1, -1}, sy[4] = {-1, -1, 1, 1};
    for (int k = 0; k < 4; ++k) mesh.vertices.emplace_back(sx[k] * l / 2, sy[k] * w / 2, 0.0);
    for (int k = 0; k < 4; ++k) {
        mesh.vertices.emplace_back(top_dx + sx[k] * top_l / 2, top_dy + sy[k] * top_w / 2, h);
    }
    // Quads as two triangles each, wound outwards; a degenerate top (ridge, apex) leaves
    // triangles of zero area, which no ray hits.
    auto quad = [&mesh](std::uint32_t a, std::uint32_t b, std::uint32_t c, std::uint32_t d) {
        mesh.triangles.push_back({a, b, c});
        mesh.triangles.push_back({a, c, d});
    };
    quad(0, 3, 2, 1);  // bottom, facing down
    quad(4, 5, 6, 7);  // top, facing up
    for (std::uint32_t k = 0; k < 4; ++k) quad(k, (k + 1) % 4, 4 + (k + 1) % 4, 4 + k);
    return mesh;
}

TriangleMesh MakeCylinderMesh(double radius, double length, int segments) {
    TriangleMesh mesh;
    // Ring vertices at both ends, then the two cap centres.
    for (int k = 0; k < segments; ++k) {
        const double a = 2.0 * M_PI * k / segments;
        const float x = static_cast<float>(radius * std::cos(a));
        const float y = static_cast<float>(radius * std::sin(a));
        mesh.vertices.emplace_back(x, y, 0.0f);
        mesh.vertices.emplace_back(x, y, static_cast<float>(length));
    }
    const auto n = static_cast<std::uint32_t>(segments);
    const std::uint32_t bottom = 2 * n, top = 2 * n + 1;
    mesh.vertices.emplace_back(0.0f, 0.0f, 0.0f);
    mesh.vertices.emplace_back(0.0f, 0.0f, static_cast<float>(length));
    for (std::uint32_t k = 0; k < n; ++k) {
        const std::uint32_t a0 = 2 * k, a1 = 2 * k + 1, b0 = 2 * ((k + 1) % n), b1 = b0 + 1;
        mesh.triangles.push_back({a0, b0, b1});
        mesh.triangles.push_back({a0, b1, a1});
        mesh.triangles.push_back({bottom, b0, a0});
        mesh.triangles.push_back({top, a1, b1});
    }
    return mesh;
}

TriangleMesh MakeLoftMesh(const std::vector<LoftRing>& rings, double exponent, int segments) {
    TriangleMesh mesh;
    const auto n = static_cast<std::uint32_t>(segments);
    const double e = 2.0 / exponent;
    for (const LoftRing& ring : rings) {
        for (std::uint32_t k = 0; k < n; ++k) {
            const double a = 2.0 * M_PI * k / n, c = std::cos(a), s = std::sin(a);
            mesh.vertices.emplace_back(ring.a * std::copysign(std::pow(std::abs(c), e), c),
                                       ring.b * std::copysign(std::pow(std::abs(s), e), s), ring.z);
        }
    }
    const auto count = static_cast<std::uint32_t>(rings.size());
    for (std::uint32_t r = 0; r + 1 < count; ++r) {
        for (std::uint32_t k = 0; k < n; ++k) {
            const std::uint32_t a0 = r * n + k, b0 = r * n + (k + 1) % n;
            mesh.triangles.push_back({a0, b0, b0 + n});
            mesh.triangles.push_back({a0, b0 + n, a0 + n});
        }
    }
    // The caps: fans about each end's centre.
    for (const std::uint32_t r : {0u, count - 1}) {
        const auto centre = static_cast<std::uint32_t>(mesh.vertices.size());
        mesh.vertices.emplace_back(0.0f, 0.0f, static_cast<float>(rings[r].z));
        for (std::uint32_t k = 0; k < n; ++k) {
            const std::uint32_t a = r * n + k, b = r * n + (k + 1) % n;
            mesh.triangles.push_back(r == 0 ? std::array<std::uint32_t, 3>{centre, b, a}
                                            : std::array<std::uint32_t, 3>{centre, a, b});
        }
    }
    return mesh;
}

}  // namespace boxd
