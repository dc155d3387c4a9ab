#pragma once
// Input and output: The measurement result of SPEC section 5, and its JSON form.

#include <array>
#include <map>
#include <nlohmann/json_fwd.hpp>
#include <optional>
#include <string>

#include "pipeline/core/result.h"
#include "pipeline/io/billing_block.h"
#include "pipeline/io/software_block.h"
#include "pipeline/io/weight_block.h"

namespace boxd {

enum class MeasurementStatus { kOk, kNoDim, kFailed };

// Why a measurement gave no dimension (status no_dim) or failed: a code of the no-dimension,
// device or interrupted categories and a one-line message.
using MeasurementReason = Error;

struct MeasuredDimensions {
    double length_m = 0.0;
    double width_m = 0.0;
    double height_m = 0.0;
    double volume_m3 = 0.0;
    std::string method = "footprint";  // footprint | pca
    // Where the box stands, in the table frame (an addition to SPEC section 5, like obb's): its
    // centre and its axes (rows: length, width and height directions). The operator page draws
    // it in the cloud.
    std::array<double, 3> center_m{};
    std::array<std::array<double, 3>, 3> axes{{{1, 0, 0}, {0, 1, 0}, {0, 0, 1}}};
};

struct OrientedBox {
    std::string method = "pca";
    std::array<double, 3> extent_m{};
    double volume_m3 = 0.0;
    std::array<double, 3> center_m{};
    std::array<std::array<double, 3>, 3> axes{};  // rows are the box axes
    std::string frame = "table";
};

struct MeasurementQuality {
    int poses = 0;
    long points = 0;
    double registration_rmse_m = 0.0;
    double confidence = 0.0;
    // The figures that decide `shape` (enclosing_cuboid.h): the footprint's fill of its
    // rectangle, the share of it the top covers, and the largest outward excess of a face over
    // its plane, relative to the box.
    std::optional<double> footprint_fill;
    std::optional<double> top_cover;
    std::optional<double> face_excess_ratio;
    // The least flat face's cells about its plane (chi-square per cell, about 1 when flat);
    // absent unless every face had enough cells seen by two views to tell. A capture stops
    // early only for a box whose faces are all told flat.
    std::optional<double> face_flatness;
    // A single view: the faces it does not show were assumed to make a cuboid.
    bool cuboid_assumed = false;
    // Why a capture stopped turning: "target_uncertainty" (every dimension's bound within the
    // capture's target), "pose_budget" (every pose of the plan taken); empty offline.
    std::string stop_reason;
};

// A 95% bound on each dimension's error, from the data.
struct DimensionUncertainty {
    double length_m = 0.0;
    double width_m = 0.0;
    double height_m = 0.0;
};

struct MeasurementResult {
    std::string id;
    std::string started_at;   // ISO-8601 UTC, millisecond precision
    std::string finished_at;  // ISO-8601 UTC, millisecond precision
    MeasurementStatus status = MeasurementStatus::kFailed;
    std::optional<MeasurementReason> reason;
    std::optional<MeasuredDimensions> dimensions;
    std::optional<OrientedBox> obb;
    std::optional<std::string> parcel_id;               // as the client gave it (a scanned barcode)
    std::string shape;                                  // "cuboid" | "irregular" with dimensions
    std::optional<DimensionUncertainty> uncertainty_m;  // with dimensions
    MeasurementQuality quality;
    std::map<std::string, double> timing_ms;  // stage name -> milliseconds
    // The station's billing of the dimensions (a station with a `billing:` section, a measured
    // object); an addition to SPEC section 5.
    std::optional<Billing> billing;
    // What the station's scale weighed (a station with a `scale:`); an addition to SPEC
    // section 5.
    std::optional<Weighing> weight;
    // The program that measured it (the daemon's); an addition to SPEC section 5.
    std::optional<SoftwareIdentity> software;
};

const char* StatusName(MeasurementStatus s);

// Returns Ok when `id` can be a parcel id: 1 to 64 printable ASCII characters (a barcode's
// text); otherwise an INVALID_INPUT error saying what is wrong, for the caller to prefix with
// the field's name.
Status CheckParcelId(const std::string& id);

// A dimension (metres) and its 95% bound as ToJson writes them (to 0.01 mm; the bound with the
// writing's own rounding, rounded up): the billing works from these, so that what a reader
// recomputes from the JSON is what was billed.
double WrittenLength(double metres);
double WrittenBound(double metres);

// Returns the SPEC section 5 JSON object of `m`.
nlohmann::json ToJson(const MeasurementResult& m);

// Returns the current UTC time as "2026-11-21T10:00:00.000Z".
std::string UtcTimestampNow();

}  // namespace boxd
