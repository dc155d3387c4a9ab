#pragma once
// The daemon's one log line per finished measurement.

#include "pipeline/io/measurement.h"

namespace boxd {

// Logs id, status, dimensions or reason, and the capture / processing / total times of `r`
// (info when measured, warning when no_dim, error when failed).
void LogMeasurement(const MeasurementResult& r);

}  // namespace boxd
