#include "drivers/sim/sensor_noise.h"

#include <cmath>

namespace boxd {

const char* NoiseModelName(NoiseModel m) {
    switch (m) {
        case NoiseModel::kNone:
            return "none";
        case NoiseModel::kKinect:
            return "kinect";
        case NoiseModel::kRealSense:
            return "realsense";
        case NoiseModel::kToF:
            return "tof";
    }
    return "none";
}

Result<NoiseModel> ParseNoiseModel(const std::string& name) {
    if (name == "none") return NoiseModel::kNone;
    if (name == "kinect") return NoiseModel::kKinect;
    if (name == "realsense") return NoiseModel::kRealSense;
    if (name == "tof") return NoiseModel::kToF;
    return Error{ErrorCode::kInvalidInput, "noise: unknown noise model '" + name +
                                               "' (expected kinect, realsense, tof or none)"};
}

Status SensorNoiseParams::Validate(const std::string& where) const {
    auto bad = [&](const std::string& field, const std::string& why) -> Status {
        return Error{ErrorCode::kInvalidInput, where + "." + field + ": " + why};
    };
    auto in = [](double x, double lo, double hi) { return std::isfinite(x) && x >= lo && x <= hi; };
    if (!in(lateral_sigma_px, 0.0, 10.0)) return bad("lateral_sigma_px", "must be in 0..10");
    if (!in(stereo_baseline_m, 1e-3, 1.0)) return bad("stereo_baseline_m", "must be in 0.001..1");
    if (!in(stereo_subpixel, 0.0, 5.0)) return bad("stereo_subpixel", "must be in 0..5");
    if (!in(tof_sigma_m, 0.0, 0.1)) return bad("tof_sigma_m", "must be in 0..0.1");
    if (!in(flying_pixel_probability, 0.0, 1.0)) {
        return bad("flying_pixel_probability", "must be in 0..1");
    }
    if (!in(flying_pixel_min_jump_m, 0.0, 10.0)) {
        return bad("flying_pixel_min_jump_m", "must be in 0..10");
    }
    if (!in(hole_fraction, 0.0, 1.0)) return bad("hole_fraction", "must be in 0..1");
    if (!in(dropout_start_deg, 0.0, 90.0)) return bad("dropout_start_deg", "must be in 0..90");
    if (!in(dropout_full_deg, dropout_start_deg, 90.0)) {
        return bad("dropout_full_deg", "must be in dropout_start_deg..90");
    }
    if (!in(min_range_m, 0.0, 100.0)) return bad("min_range_m", "must be in 0..100");
    if (std::isnan(max_range_m) || max_range_m <= min_range_m) {
        return bad("max_range_m", "must be greater than min_range_m");
    }
    if (!in(shadow_baseline_m, -1.0, 1.0)) return bad("shadow_baseline_m", "must be in -1..1");
    if (edge_fattening_px < 0 || edge_fattening_px > 20) {
        return bad("edge_fattening_px", "must be in 0..20");
    }
    if (!in(correlated_sigma_m, 0.0, 0.1)) return bad("correlated_sigma_m", "must be in 0..0.1");
    if (!in(correlation_px, 2.0, 1000.0)) return bad("correlation_px", "must be in 2..1000");
    if (!in(fixed_pattern_m, 0.0, 0.1)) return bad("fixed_pattern_m", "must be in 0..0.1");
    if (!in(fixed_pattern_px, 2.0, 1000.0)) return bad("fixed_pattern_px", "must be in 2..1000");
    if (!in(multipath_albedo, 0.0, 1.0)) return bad("multipath_albedo", "must be in 0..1");
    return OkStatus();
}

SensorNoiseParams DefaultSensorNoise(NoiseModel model) {
    SensorNoiseParams p;
    p.axial = model;
    switch (model) {
        case NoiseModel::kNone:
            break;
        case NoiseModel::kKinect:
            // Lateral noise of 0.5-0.8 px (Nguyen et al. 2012); structured light loses the
            // projected pattern at grazing angles beyond about 75 degrees.
            p.lateral_sigma_px = 0.65;
            p.disparity_quantisation = true;
            p.flying_pixel_probability = 0.35;
            p.hole_fraction = 0.005;
            p.dropout_start_deg = 70.0;
            p.dropout_full_deg = 80.0;
            p.min_range_m = 0.4;
            p.max_range_m = 4.5;
            break;
        case NoiseModel::kRealSense:
            // D4xx: sub-pixel stereo matching keeps edges sharper (fewer mixed pixels) and the
            // lateral error smaller than the Kinect's.
            p.lateral_sigma_px = 0.3;
            p.flying_pixel_probability = 0.1;
            p.hole_fraction = 0.005;
            p.dropout_start_deg = 72.0;
            p.dropout_full_deg = 82.0;
            p.min_range_m = 0.2;
            p.max_range_m = 6.0;
            break;
        case NoiseModel::kToF:
            // Kinect v2 / Azure Kinect class: about 1.5 mm at 1 m head-on (Fankhauser et al.,
            // "Kinect v2 for mobile robot navigation", ICAR 2015), no matching window (little
            // lateral error) but a pixel straddling an edge always mixes both returns; low
            // amplitudes are invalidated at grazing incidence; the light that reaches a point
            // by way of another surface lengthens its path (multipath.h), cardboard reflecting
            // about half of the near infrared.
            p.lateral_sigma_px = 0.15;
            p.flying_pixel_probability = 0.6;
            p.hole_fraction = 0.002;
            p.dropout_start_deg = 75.0;
            p.dropout_full_deg = 85.0;
            p.min_range_m = 0.25;
            p.max_range_m = 5.0;
            p.multipath_albedo = 0.5;
            break;
    }
    return p;
}

}  // namespace boxd
