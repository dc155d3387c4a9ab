#pragma once
// Core: Planar rigid motions (SE(2)) in the table frame. Every turntable view differs from pose 0
// by a rotation about the table normal plus a shift in the table plane, so registration works in
// (x, y, yaw) and leaves z untouched.

#include <Eigen/Core>
#include <cmath>

namespace boxd {

struct Se2;

// A motion with its cosine and sine worked out once, for applying it to many points; the same
// arithmetic as Se2::Apply.
struct Se2Map {
    explicit Se2Map(const Se2& t);
    Eigen::Vector3f operator()(const Eigen::Vector3f& p) const {
        return {static_cast<float>(c * p.x() - s * p.y() + x),
                static_cast<float>(s * p.x() + c * p.y() + y), p.z()};
    }
    double c, s, x, y;
};

struct Se2 {
    double x = 0.0;
    double y = 0.0;
    double yaw = 0.0;  // radians, counter-clockwise about +z

    // Returns p rotated by yaw about the origin and then shifted by (x, y); z is kept.
    Eigen::Vector3f Apply(const Eigen::Vector3f& p) const { return Se2Map(*this)(p); }
    Eigen::Vector2d Apply(const Eigen::Vector2d& p) const {
        const double c = std::cos(yaw), s = std::sin(yaw);
        return {c * p.x() - s * p.y() + x, s * p.x() + c * p.y() + y};
    }
    // Returns this ∘ other (other applied first).
    Se2 Compose(const Se2& other) const {
        const Eigen::Vector2d t = Apply(Eigen::Vector2d(other.x, other.y));
        return {t.x(), t.y(), WrapAngle(yaw + other.yaw)};
    }
    // Returns the inverse motion.
    Se2 Inverse() const {
        const double c = std::cos(yaw), s = std::sin(yaw);
        return {-(c * x + s * y), -(-s * x + c * y), -yaw};
    }

    // Returns the rotation by `angle` about the in-plane point `center`.
    static Se2 RotationAbout(double angle, const Eigen::Vector2d& center) {
        Se2 r{0.0, 0.0, angle};
        const Eigen::Vector2d rc = r.Apply(center);
        r.x = center.x() - rc.x();
        r.y = center.y() - rc.y();
        return r;
    }
    // Returns `a` wrapped into (-pi, pi].
    static double WrapAngle(double a) { return std::remainder(a, 2.0 * M_PI); }
};

inline Se2Map::Se2Map(const Se2& t) : c(std::cos(t.yaw)), s(std::sin(t.yaw)), x(t.x), y(t.y) {}

// Returns the left-perturbation difference a ∘ b⁻¹ as (x, y, yaw): the small motion that takes
// b onto a (zero when they are equal).
inline Eigen::Vector3d Se2Difference(const Se2& a, const Se2& b) {
    const Se2 d = a.Compose(b.Inverse());
    return {d.x, d.y, d.yaw};
}

}  // namespace boxd
