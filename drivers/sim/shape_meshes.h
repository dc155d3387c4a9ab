#pragma once
// Meshes of the synthetic station's shapes whose widest part or highest point is where a camera
// above reads least: a sack bulging low, a bottle lying on its side, a carton on a chamfered base,
// a small carton standing on a larger one, a carton with a strap looped above its top. Each is
// built in the object's own frame (origin at its footprint's centre on the table top, +x along
// its length, +z up) and fills the l x w x h cuboid it is asked for exactly, which is then its
// smallest enclosing cuboid (each is symmetric about, or aligned with, its own axes).

#include "drivers/sim/triangle_mesh.h"

namespace boxd {

// A sack: squarish cross-sections (a superellipse of exponent 3), widest (l x w) a third of the
// way up, drawn in to 0.72 of that where it rests on the table (its bulging bottom overhangs the
// table), narrowing to 0.85 higher up and gathered into a dome at the top.
TriangleMesh MakeSackMesh(double l, double w, double h);

// A bottle lying along x on its side: a body of diameter d with a rounded base, a shoulder from
// 62% to 80% of its length l, a neck of 0.35 d and a lip of 0.4 d.
TriangleMesh MakeLyingBottleMesh(double l, double d);

// A carton l x w x h whose base is chamfered at 45 degrees: its sides come in by `chamfer` over
// the bottom `chamfer` of its height.
TriangleMesh MakeChamferedBoxMesh(double l, double w, double h, double chamfer);

// A carton of 0.55 l x 0.6 w x 0.4 h standing on an l x w x 0.6 h one, off centre by 0.2 l
// along x (within the lower one's top).
TriangleMesh MakeBoxOnBoxMesh(double l, double w, double h);

// A carton with a carrying strap looped above its top along x: a 25 mm wide, 4 mm thick band
// rising from the top at +-0.25 l to a bar at height h; the loop stands 15% of h above the
// carton (20 to 50 mm).
TriangleMesh MakeHandleBoxMesh(double l, double w, double h);

}  // namespace boxd
