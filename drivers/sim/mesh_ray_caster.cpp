#include "drivers/sim/mesh_ray_caster.h"

#include <embree3/rtcore.h>

#include <cmath>
#include <limits>
#include <stdexcept>

namespace boxd {

namespace {

// One Embree device for the process: it owns no scene state, and building it costs more than a
// scene of a few thousand triangles.
RTCDevice Device() {
    // One build thread: meshes are small, and the renderer already works on every core.
    static RTCDevice device = rtcNewDevice("threads=1,set_affinity=0");
    return device;
}

}  // namespace

struct MeshRayCaster::Impl {
    RTCScene scene = nullptr;
};

MeshRayCaster::MeshRayCaster(const TriangleMesh& mesh) : impl_(std::make_unique<Impl>()) {
    RTCDevice device = Device();
    if (device == nullptr) throw std::runtime_error("embree: no device");
    impl_->scene = rtcNewScene(device);
    // Robust traversal: rays through shared edges and vertices never slip between triangles.
    rtcSetSceneFlags(impl_->scene, RTC_SCENE_FLAG_ROBUST);
    rtcSetSceneBuildQuality(impl_->scene, RTC_BUILD_QUALITY_MEDIUM);
    RTCGeometry geometry = rtcNewGeometry(device, RTC_GEOMETRY_TYPE_TRIANGLE);
    auto* v = static_cast<float*>(rtcSetNewGeometryBuffer(geometry, RTC_BUFFER_TYPE_VERTEX, 0,
                                                          RTC_FORMAT_FLOAT3, 3 * sizeof(float),
                                                          mesh.vertices.size()));
    for (std::size_t i = 0; i < mesh.vertices.size(); ++i) {
        v[3 * i] = mesh.vertices[i].x();
        v[3 * i + 1] = mesh.vertices[i].y();
        v[3 * i + 2] = mesh.vertices[i].z();
    }
    auto* t = static_cast<unsigned*>(rtcSetNewGeometryBuffer(geometry, RTC_BUFFER_TYPE_INDEX, 0,
                                                             RTC_FORMAT_UINT3, 3 * sizeof(unsigned),
                                                             mesh.triangles.size()));
    for (std::size_t i = 0; i < mesh.triangles.size(); ++i) {
        for (int k = 0; k < 3; ++k) t[3 * i + k] = mesh.triangles[i][static_cast<std::size_t>(k)];
    }
    rtcCommitGeometry(geometry);
    rtcAttachGeometry(impl_->scene, geometry);
    rtcReleaseGeometry(geometry);
    rtcCommitScene(impl_->scene);
}

MeshRayCaster::~MeshRayCaster() {
    if (impl_ && impl_->scene) rtcReleaseScene(impl_->scene);
}

bool MeshRayCaster::Intersect(const Eigen::Vector3d& origin, const Eigen::Vector3d& direction,
                              double t_max, Hit& hit) const {
    RTCIntersectContext context;
    rtcInitIntersectContext(&context);
    RTCRayHit rh{};
    rh.ray.org_x = static_cast<float>(origin.x());
    rh.ray.org_y = static_cast<float>(origin.y());
    rh.ray.org_z = static_cast<float>(origin.z());
    rh.ray.dir_x = static_cast<float>(direction.x());
    rh.ray.dir_y = static_cast<float>(direction.y());
    rh.ray.dir_z = static_cast<float>(direction.z());
    rh.ray.tnear = 0.0f;
    rh.ray.tfar =
        std::isfinite(t_max) ? static_cast<float>(t_max) : std::numeric_limits<float>::infinity();
    rh.ray.mask = 0xFFFFFFFFu;
    rh.ray.flags = 0;
    rh.hit.geomID = RTC_INVALID_GEOMETRY_ID;
    rh.hit.instID[0] = RTC_INVALID_GEOMETRY_ID;
    rtcIntersect1(impl_->scene, &context, &rh);
    if (rh.hit.geomID == RTC_INVALID_GEOMETRY_ID) return false;
    const Eigen::Vector3d n(rh.hit.Ng_x, rh.hit.Ng_y, rh.hit.Ng_z);
    hit.t = rh.ray.tfar;
    const double nn = n.norm() * direction.norm();
    hit.cos_incidence = nn > 0.0 ? std::min(1.0, std::abs(n.dot(direction)) / nn) : 1.0;
    return true;
}

}  // namespace boxd
