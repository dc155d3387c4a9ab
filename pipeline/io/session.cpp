#include "pipeline/io/session.h"

#include <cmath>
#include <cstdio>

namespace boxd {

double TurntableAngleRad(double angle_deg, TurntableDirection direction) {
    const double rad = angle_deg * M_PI / 180.0;
    return direction == TurntableDirection::kCcw ? rad : -rad;
}

std::vector<double> TurntableAnglesRad(const std::vector<double>& angles_deg,
                                       TurntableDirection direction) {
    std::vector<double> out;
    for (double a : angles_deg) out.push_back(TurntableAngleRad(a, direction));
    return out;
}

double Session::PoseAngleRad(std::size_t i) const {
    return TurntableAngleRad(poses.at(i).angle_deg, direction);
}

std::string SessionFramePath(std::size_t pose, std::size_t frame) {
    char buf[64];
    std::snprintf(buf, sizeof(buf), "pose_%03zu/frame_%02zu.png", pose, frame);
    return buf;
}

std::vector<double> Session::PoseAnglesRad() const {
    return TurntableAnglesRad(PoseAnglesDeg(), direction);
}

std::vector<double> Session::PoseAnglesDeg() const {
    std::vector<double> angles;
    for (const SessionPose& pose : poses) angles.push_back(pose.angle_deg);
    return angles;
}

}  // namespace boxd
