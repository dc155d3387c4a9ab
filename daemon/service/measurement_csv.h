#pragma once
// The stored measurements as CSV (RFC 4180) for a warehouse system: GET /v1/measurements.csv and
// `boxd export`. One row per measurement, oldest first, with its dimensions and bounds in mm,
// the weight, and the billing block flattened — the billed dimensions, volume and each carrier's
// dimensional and billable weight (a column pair per carrier named in any row). Text a person
// typed (a parcel id, a reason) that a spreadsheet would run as a formula (=, +, -, @, tab, CR
// first) is prefixed with an apostrophe (OWASP's advice on CSV injection).

#include <nlohmann/json.hpp>
#include <optional>
#include <string>
#include <vector>

#include "pipeline/core/result.h"

namespace boxd {

// Returns the CSV of `records` (measurement JSON objects as stored, oldest first), header first.
std::string MeasurementsCsv(const std::vector<nlohmann::json>& records);

// Returns `since` when it is a UTC date or time a record's finished_at compares with
// ("2026-12-05", "2026-12-05T10:00", "2026-12-05T10:00:00", "2026-12-05T10:00:00.000Z"), or an
// INVALID_INPUT error saying the form.
Result<std::string> CheckSince(const std::string& since);

}  // namespace boxd
