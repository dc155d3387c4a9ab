#pragma once
// Triangle meshes of the synthetic station's objects (parcels that are not ideal boxes): a
// box with rounded edges and bulging faces, straps, labels and flaps as thin boxes, cylinders.
// Built in the object's own frame: origin at the centre of its footprint on the table top, +z up,
// +x along the length.

#include <Eigen/Core>
#include <array>
#include <cstdint>
#include <vector>

namespace boxd {

struct TriangleMesh {
    std::vector<Eigen::Vector3f> vertices;
    std::vector<std::array<std::uint32_t, 3>> triangles;  // counter-clockwise seen from outside

    // Appends `other`'s triangles.
    void Append(const TriangleMesh& other);
    // Returns this mesh moved by the rigid motion (R, t): v -> R v + t.
    TriangleMesh Transformed(const Eigen::Matrix3d& rotation, const Eigen::Vector3d& t) const;
    // Returns the axis-aligned bounds (min, max) of the vertices.
    std::array<Eigen::Vector3d, 2> Bounds() const;
};

// How a rounded, bulging box deviates from the ideal l x w x h box (all 0: the ideal box).
struct BoxDeformation {
    double edge_radius_m = 0.0;  // edges and corners rounded with this radius
    double side_bulge_m = 0.0;   // each side face pushed out by this much at its middle
    double top_bulge_m = 0.0;    // the top face, likewise
};

// Returns the closed surface of an l x w x h box standing on z = 0, centred on the z axis,
// deformed by `deformation` (the bulge of a face falls to zero at its edges as a product of
// parabolas, the shape of a full carton's panel), its faces cut into `cells` x `cells` quads.
TriangleMesh MakeBoxMesh(double l, double w, double h, const BoxDeformation& deformation,
                         int cells = 64);

// Returns the axis-aligned box [lo, hi] (a strap, a label, a flap panel before it is turned).
TriangleMesh MakeCuboidMesh(const Eigen::Vector3d& lo, const Eigen::Vector3d& hi);

// Returns a closed solid with planar faces standing on z = 0: an l x w rectangle centred on the z
// axis at the bottom, and at height h a top_l x top_w rectangle centred at (top_dx, top_dy). A
// top of zero width is a ridge (a prism or wedge lying on a face), of zero size an apex (a
// pyramid); a smaller top a frustum (a tapered carton).
TriangleMesh MakeTaperedBoxMesh(double l, double w, double h, double top_l, double top_w,
                                double top_dx = 0.0, double top_dy = 0.0);

// One cross-section of a loft: at height z, the superellipse |x / a|^p + |y / b|^p = 1.
struct LoftRing {
    double z = 0.0, a = 0.0, b = 0.0;
};

// Returns the closed surface through `rings` (z increasing), each a superellipse of `exponent`
// p (2: an ellipse, larger: squarer) of `segments` points (a multiple of 4, so that the ends of
// its axes are among them), closed by a flat cap at either end.
TriangleMesh MakeLoftMesh(const std::vector<LoftRing>& rings, double exponent,
                          int segments = 144);

// Returns a closed cylinder of `radius` and `length` along +z from z = 0, with `segments` sides.
TriangleMesh MakeCylinderMesh(double radius, double length, int segments = 360);

}  // namespace boxd
