#pragma once
// MeshRayCaster: the first hit of a ray on a triangle mesh, through Embree (Intel's ray-tracing
// kernels, Debian's libembree-dev): the synthetic station renders its non-box objects with it.

#include <Eigen/Core>
#include <memory>

#include "drivers/sim/triangle_mesh.h"

namespace boxd {

class MeshRayCaster {
public:
    // Builds the acceleration structure of `mesh` (any frame; rays are given in the same).
    explicit MeshRayCaster(const TriangleMesh& mesh);
    ~MeshRayCaster();
    MeshRayCaster(const MeshRayCaster&) = delete;
    MeshRayCaster& operator=(const MeshRayCaster&) = delete;

    struct Hit {
        double t = 0.0;              // the ray parameter: the hit is origin + t * direction
        double cos_incidence = 1.0;  // |cos| of the angle between the ray and the surface normal
    };
    // Returns true and the first hit with 0 < t < t_max of origin + t * direction (direction
    // need not be unit length). Thread-safe.
    bool Intersect(const Eigen::Vector3d& origin, const Eigen::Vector3d& direction, double t_max,
                   Hit& hit) const;

private:
    struct Impl;
    std::unique_ptr<Impl> impl_;
};

}  // namespace boxd
