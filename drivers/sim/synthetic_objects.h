#pragma once
// The objects of the synthetic station that are not ideal boxes — parcels as they come: rounded,
// bulging, strapped, labelled, with an open flap; tubes standing or lying; an L-shaped pack; a
// soft bag; prisms, wedges, frusta, pyramids and the shapes of shape_meshes.h; a second parcel;
// a hand reaching in — as triangle meshes, and the smallest cuboid each fits in (the answer a
// carrier bills, SPEC section 5).

#include <optional>
#include <string>

#include "drivers/sim/synthetic_station.h"
#include "drivers/sim/triangle_mesh.h"
#include "pipeline/core/result.h"

namespace boxd {

// Returns the shape's name: "box", "cylinder", "lying_cylinder", "l_shape", "bag", "prism", ...
const char* SyntheticShapeName(SyntheticShape shape);
// Returns the shape named `name`, or an error naming it.
Result<SyntheticShape> ParseSyntheticShape(const std::string& name);

// Returns an error naming the first field of `object` (a config's `field`) that does not make a
// shape (a cylinder's length and width are its diameter, a lying cylinder's width and height).
Status ValidateSyntheticObject(const SyntheticBox& object, const std::string& field);

// Returns the surface of `object` in its own frame: origin at its footprint's centre on the
// table top, +x along its length, +z up. Not defined for the ideal box (rendered exactly).
TriangleMesh SyntheticObjectMesh(const SyntheticBox& object);

// Returns the smallest enclosing cuboid standing on the table of `object` (length >= width).
// Every shape here is symmetric about, or aligned with, its own x and y axes, so that cuboid is
// its bounding box in its own frame: the ideal box's exactly, the others' from their meshes.
BoxDimensions SyntheticEnclosingCuboid(const SyntheticBox& object);

// Returns the largest distance from the axis that `object` reaches at pose 0 (its offset and
// yaw, moved by (dx, dy, dyaw_deg)).
double SyntheticObjectReach(const SyntheticBox& object, double dx = 0.0, double dy = 0.0,
                            double dyaw_deg = 0.0);

// Returns every mesh-rendered object of `config` at table angle `table_angle_rad` in the table
// frame — the main object when it is not the ideal box, the extra objects, and in pose
// `config.intruder_pose` the hand — or nullopt when there is none.
std::optional<TriangleMesh> PlacedObjectMeshes(const SyntheticStationConfig& config,
                                               double table_angle_rad, int pose_index);

}  // namespace boxd
