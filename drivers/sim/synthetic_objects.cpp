#include "drivers/sim/synthetic_objects.h"

#include <spdlog/fmt/fmt.h>
#include <spdlog/fmt/ranges.h>

#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>
#include <string>
#include <vector>

#include "drivers/sim/shape_meshes.h"

namespace boxd {

namespace {

constexpr double kDegToRad = M_PI / 180.0;

struct ShapeName {
    SyntheticShape shape;
    const char* name;
};
constexpr ShapeName kShapeNames[] = {{SyntheticShape::kBox, "box"},
                                     {SyntheticShape::kCylinder, "cylinder"},
                                     {SyntheticShape::kLyingCylinder, "lying_cylinder"},
                                     {SyntheticShape::kLShape, "l_shape"},
                                     {SyntheticShape::kBag, "bag"},
                                     {SyntheticShape::kPrism, "prism"},
                                     {SyntheticShape::kWedge, "wedge"},
                                     {SyntheticShape::kFrustum, "frustum"},
                                     {SyntheticShape::kPyramid, "pyramid"},
                                     {SyntheticShape::kSack, "sack"},
                                     {SyntheticShape::kLyingBottle, "lying_bottle"},
                                     {SyntheticShape::kChamfered, "chamfered"},
                                     {SyntheticShape::kBoxOnBox, "box_on_box"},
                                     {SyntheticShape::kHandle, "handle"}};

Eigen::Matrix3d Yaw(double rad) {
    return Eigen::AngleAxisd(rad, Eigen::Vector3d::UnitZ()).matrix();
}

// A box with its real-parcel features: rounded edges, bulges, a strap over the top and down both
// ends, a label on the +y side, a top flap hinged at the +x top edge.
TriangleMesh ParcelMesh(const SyntheticBox& b) {
    const double l = b.length_m, w = b.width_m, h = b.height_m;
    TriangleMesh mesh = MakeBoxMesh(l, w, h, {b.edge_radius_m, b.bulge_m, b.bulge_top_m});
    if (b.strap_thickness_m > 0.0) {
        const double t = b.strap_thickness_m, s = b.strap_width_m / 2.0;
        // The band lies on the faces' outermost points (a bulge lifts it).
        const double top = h + b.bulge_top_m, end = l / 2.0 + b.bulge_m;
        mesh.Append(MakeCuboidMesh({-end - t, -s, top}, {end + t, s, top + t}));
        mesh.Append(MakeCuboidMesh({end, -s, 0.0}, {end + t, s, top + t}));
        mesh.Append(MakeCuboidMesh({-end - t, -s, 0.0}, {-end, s, top + t}));
    }
    if (b.label_thickness_m > 0.0) {
        const double y = w / 2.0 + b.bulge_m;
        mesh.Append(
            MakeCuboidMesh({-0.2 * l, y, 0.3 * h}, {0.2 * l, y + b.label_thickness_m, 0.7 * h}));
    }
    if (b.flap_deg > 0.0) {
        // A panel half the length long and 3 mm thick, closed (0 degrees) it lies on the top;
        // opened it turns about the +x top edge.
        const double t = 0.003;
        const TriangleMesh panel = MakeCuboidMesh({-l / 2.0, -w / 2.0, 0.0}, {0.0, w / 2.0, t});
        const Eigen::Matrix3d turn =
            Eigen::AngleAxisd(b.flap_deg * kDegToRad, Eigen::Vector3d::UnitY()).matrix();
        mesh.Append(panel.Transformed(turn, Eigen::Vector3d(l / 2.0, 0.0, h + b.bulge_top_m)));
    }
    return mesh;
}

}  // namespace

const char* SyntheticShapeName(SyntheticShape shape) {
    for (const auto& s : kShapeNames) {
        if (s.shape == shape) return s.name;
    }
    return "box";
}

Result<SyntheticShape> ParseSyntheticShape(const std::string& name) {
    for (const auto& s : kShapeNames) {
        if (name == s.name) return s.shape;
    }
    std::vector<std::string> names;
    for (const auto& s : kShapeNames) names.emplace_back(s.name);
    return Error{ErrorCode::kInvalidInput,
                 fmt::format("shape: must be one of {}, got '{}'", fmt::join(names, ", "), name)};
}

Status ValidateSyntheticObject(const SyntheticBox& b, const std::string& field) {
    auto bad = [&field](const std::string& f, const std::string& why) -> Status {
        return Error{ErrorCode::kInvalidInput, field + "." + f + ": " + why};
    };
    for (auto [name, v] :
         {std::pair{"length_m", b.length_m}, {"width_m", b.width_m}, {"height_m", b.height_m}}) {
        if (!std::isfinite(v) || v <= 0.0 || v > 5.0) return bad(name, "must be in (0, 5] metres");
    }
    if (!std::isfinite(b.offset_x_m)) return bad("offset_x_m", "must be finite");
    if (!std::isfinite(b.offset_y_m)) return bad("offset_y_m", "must be finite");
    if (!std::isfinite(b.yaw_deg)) return bad("yaw_deg", "must be finite");
    const double smallest = std::min({b.length_m, b.width_m, b.height_m});
    for (auto [name, v] : {std::pair{"edge_radius_m", b.edge_radius_m},
                           {"bulge_m", b.bulge_m},
                           {"bulge_top_m", b.bulge_top_m},
                           {"strap_thickness_m", b.strap_thickness_m},
                           {"label_thickness_m", b.label_thickness_m}}) {
        if (!std::isfinite(v) || v < 0.0 || v > smallest / 2.0) {
            return bad(name, "must be in 0..half the smallest side");
        }
    }
    if (!std::isfinite(b.strap_width_m) || b.strap_width_m <= 0.0 || b.strap_width_m > b.width_m) {
        return bad("strap_width_m", "must be in (0, width_m]");
    }
    if (!std::isfinite(b.flap_deg) || b.flap_deg < 0.0 || b.flap_deg > 180.0) {
        return bad("flap_deg", "must be in 0..180 degrees");
    }
    const bool features = b.edge_radius_m > 0.0 || b.bulge_m > 0.0 || b.bulge_top_m > 0.0 ||
                          b.strap_thickness_m > 0.0 || b.label_thickness_m > 0.0 ||
                          b.flap_deg > 0.0;
    if (features && b.shape != SyntheticShape::kBox) {
        return bad("shape", "edges, bulges, straps, labels and flaps belong to a box");
    }
    const bool frustum = b.shape == SyntheticShape::kFrustum;
    const bool chamfered = b.shape == SyntheticShape::kChamfered;
    if (!std::isfinite(b.taper_m) || b.taper_m < 0.0 ||
        (frustum && !(b.taper_m > 0.0 && b.taper_m < std::min(b.length_m, b.width_m) / 2.0))) {
        return bad("taper_m", "a frustum's is in (0, half its base's smaller side)");
    }
    if (chamfered && !(b.taper_m > 0.0 && b.taper_m <= std::min(b.length_m, b.width_m) / 4.0 &&
                       b.taper_m <= b.height_m / 2.0)) {
        return bad("taper_m",
                   "a chamfer is in (0, a quarter of the base's smaller side and half "
                   "the height]");
    }
    if (!frustum && !chamfered && b.taper_m > 0.0) {
        return bad("taper_m", "belongs to a frustum or a chamfered carton");
    }
    if (b.shape == SyntheticShape::kCylinder && std::abs(b.length_m - b.width_m) > 1e-9) {
        return bad("width_m", "a standing cylinder's length and width are its diameter");
    }
    if ((b.shape == SyntheticShape::kLyingCylinder || b.shape == SyntheticShape::kLyingBottle) &&
        std::abs(b.width_m - b.height_m) > 1e-9) {
        return bad("height_m", "a lying cylinder's or bottle's width and height are its diameter");
    }
    if (b.shape == SyntheticShape::kHandle && (b.width_m < 0.03 || b.height_m < 0.06)) {
        return bad("shape", "a carton with a handle is at least 30 mm wide and 60 mm high");
    }
    return OkStatus();
}

TriangleMesh SyntheticObjectMesh(const SyntheticBox& b) {
    const double l = b.length_m, w = b.width_m, h = b.height_m;
    switch (b.shape) {
        case SyntheticShape::kCylinder:
            return MakeCylinderMesh(l / 2.0, h);
        case SyntheticShape::kLyingCylinder: {
            // Along +x, resting on the table on its side.
            const Eigen::Matrix3d to_x =
                Eigen::AngleAxisd(M_PI / 2.0, Eigen::Vector3d::UnitY()).matrix();
            return MakeCylinderMesh(w / 2.0, l).Transformed(to_x, {-l / 2.0, 0.0, w / 2.0});
        }
        case SyntheticShape::kLShape: {
            // The l x w footprint without its (+x, +y) quarter: two blocks side by side.
            TriangleMesh mesh = MakeCuboidMesh({-l / 2.0, -w / 2.0, 0.0}, {l / 2.0, 0.0, h});
            mesh.Append(MakeCuboidMesh({-l / 2.0, 0.0, 0.0}, {0.0, w / 2.0, h}));
            return mesh;
        }
        case SyntheticShape::kBag: {
            // A soft bag: well rounded, its sides and top bulging; l x w x h is its core.
            const double r = 0.3 * std::min({l, w, h});
            return MakeBoxMesh(l, w, h, {r, 0.06 * std::min(l, w), 0.08 * h});
        }
        case SyntheticShape::kPrism:
            return MakeTaperedBoxMesh(l, w, h, l, 0.0);
        case SyntheticShape::kWedge:
            return MakeTaperedBoxMesh(l, w, h, l, 0.0, 0.0, -w / 2.0);
        case SyntheticShape::kFrustum:
            return MakeTaperedBoxMesh(l, w, h, l - 2.0 * b.taper_m, w - 2.0 * b.taper_m);
        case SyntheticShape::kPyramid:
            return MakeTaperedBoxMesh(l, w, h, 0.0, 0.0);
        case SyntheticShape::kSack:
            return MakeSackMesh(l, w, h);
        case SyntheticShape::kLyingBottle:
            return MakeLyingBottleMesh(l, w);
        case SyntheticShape::kChamfered:
            return MakeChamferedBoxMesh(l, w, h, b.taper_m);
        case SyntheticShape::kBoxOnBox:
            return MakeBoxOnBoxMesh(l, w, h);
        case SyntheticShape::kHandle:
            return MakeHandleBoxMesh(l, w, h);
        case SyntheticShape::kBox:
            break;
    }
    return ParcelMesh(b);
}

BoxDimensions SyntheticEnclosingCuboid(const SyntheticBox& b) {
    if (b.IsIdealBox()) {
        return {std::max(b.length_m, b.width_m), std::min(b.length_m, b.width_m), b.height_m};
    }
    const auto [lo, hi] = SyntheticObjectMesh(b).Bounds();
    const Eigen::Vector3d e = hi - lo;
    return {std::max(e.x(), e.y()), std::min(e.x(), e.y()), hi.z()};
}

double SyntheticObjectReach(const SyntheticBox& b, double dx, double dy, double dyaw_deg) {
    Eigen::Vector3d lo(-b.length_m / 2.0, -b.width_m / 2.0, 0.0), hi = -lo;
    if (!b.IsIdealBox()) {
        const auto bounds = SyntheticObjectMesh(b).Bounds();
        lo = bounds[0];
        hi = bounds[1];
    }
    const Eigen::Matrix3d r = Yaw((b.yaw_deg + dyaw_deg) * kDegToRad);
    const Eigen::Vector3d t(b.offset_x_m + dx, b.offset_y_m + dy, 0.0);
    double reach = 0.0;
    for (double x : {lo.x(), hi.x()}) {
        for (double y : {lo.y(), hi.y()}) {
            reach = std::max(reach, (r * Eigen::Vector3d(x, y, 0.0) + t).head<2>().norm());
        }
    }
    return reach;
}

std::optional<TriangleMesh> PlacedObjectMeshes(const SyntheticStationConfig& config,
                                               double table_angle_rad, int pose_index) {
    TriangleMesh all;
    const Eigen::Matrix3d table = Yaw(table_angle_rad);
    // An object stands on the table at its offset, turned by its yaw; the table turns them all.
    auto place = [&](const SyntheticBox& b, double dx, double dy, double dyaw_deg) {
        const Eigen::Matrix3d r = table * Yaw((b.yaw_deg + dyaw_deg) * kDegToRad);
        const Eigen::Vector3d t =
            table * Eigen::Vector3d(b.offset_x_m + dx, b.offset_y_m + dy, 0.0);
        all.Append(SyntheticObjectMesh(b).Transformed(r, t));
    };
    if (!config.box.IsIdealBox()) {
        const bool moved = config.moved_at_pose && pose_index >= *config.moved_at_pose;
        place(config.box, moved ? config.moved_dx_m : 0.0, moved ? config.moved_dy_m : 0.0,
              moved ? config.moved_dyaw_deg : 0.0);
    }
    for (const SyntheticBox& b : config.extra_objects) place(b, 0.0, 0.0, 0.0);
    if (config.intruder_pose && pose_index == *config.intruder_pose) {
        // A hand on an arm, reaching in over the table's +x edge (fixed in the room, not turning
        // with the table) to just beside the object, a little above the table top.
        const double tip = SyntheticObjectReach(config.box) + 0.03;
        const double z = std::min(0.15, 0.5 * config.box.height_m);
        all.Append(MakeCuboidMesh({tip, -0.045, z}, {tip + 0.09, 0.045, z + 0.04}));
        all.Append(MakeCuboidMesh({tip + 0.09, -0.035, z + 0.005}, {tip + 0.60, 0.035, z + 0.065}));
    }
    if (all.triangles.empty()) return std::nullopt;
    return all;
}

}  // namespace boxd
