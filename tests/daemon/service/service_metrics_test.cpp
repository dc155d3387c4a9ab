// The Prometheus exposition of ServiceMetrics: every line parses, counters count by status and
// reason, histograms are cumulative with a +Inf bucket equal to their count.
#include "daemon/service/service_metrics.h"

#include <gtest/gtest.h>

#include "tests/support/prometheus_text.h"

namespace boxd {
namespace {

MeasurementResult Finished(MeasurementStatus status, std::optional<ErrorCode> code, double total_ms,
                           double processing_ms) {
    MeasurementResult r;
    r.status = status;
    if (code) r.reason = MeasurementReason{*code, "why"};
    r.timing_ms["total"] = total_ms;
    r.timing_ms["processing"] = processing_ms;
    return r;
}

TEST(ServiceMetrics, NothingRecordedIsAllZeroAndParses) {
    ServiceMetrics metrics;
    MetricsContext context;
    context.uptime_s = 7;
    const auto samples = test::ParsePrometheus(metrics.Text(context));
    EXPECT_EQ(samples.at("boxd_measurements_total{status=\"ok\"}"), 0);
    EXPECT_EQ(samples.at("boxd_measurements_total{status=\"no_dim\"}"), 0);
    EXPECT_EQ(samples.at("boxd_measurement_cycle_seconds_count"), 0);
    EXPECT_EQ(samples.at("boxd_measurement_cycle_seconds_bucket{le=\"+Inf\"}"), 0);
    EXPECT_EQ(samples.at("boxd_device_faults_total{device=\"turntable\"}"), 0);
    EXPECT_EQ(samples.at("boxd_state{state=\"idle\"}"), 1);
    EXPECT_EQ(samples.at("boxd_state{state=\"error\"}"), 0);
    EXPECT_EQ(samples.at("boxd_uptime_seconds"), 7);
    EXPECT_EQ(samples.at("boxd_calibrated"), 0);
    EXPECT_EQ(samples.count("boxd_calibration_age_seconds"), 0u) << "no calibration, no age";
    EXPECT_EQ(samples.count("boxd_build_info{version=\"" BOXD_TEST_VERSION "\"}"), 1u);
}

TEST(ServiceMetrics, CountsByStatusAndReasonAndTimesInCumulativeBuckets) {
    ServiceMetrics metrics;
    metrics.RecordMeasurement(Finished(MeasurementStatus::kOk, std::nullopt, 2800, 120));
    metrics.RecordMeasurement(Finished(MeasurementStatus::kOk, std::nullopt, 4100, 600));
    metrics.RecordMeasurement(
        Finished(MeasurementStatus::kNoDim, ErrorCode::kMultipleObjects, 3000, 90));
    metrics.RecordMeasurement(
        Finished(MeasurementStatus::kFailed, ErrorCode::kTurntableError, 500, 0));
    metrics.RecordFault(ErrorCode::kCameraError);
    metrics.RecordFault(ErrorCode::kScaleError);
    metrics.RecordFault(ErrorCode::kScaleError);
    metrics.RecordFault(ErrorCode::kWrongReference);  // not a device fault: ignored
    MetricsContext context;
    context.state = "error";
    context.calibrated = true;
    context.calibration_age_s = 3600;
    const auto s = test::ParsePrometheus(metrics.Text(context));
    EXPECT_EQ(s.at("boxd_measurements_total{status=\"ok\"}"), 2);
    EXPECT_EQ(s.at("boxd_measurements_total{status=\"no_dim\"}"), 1);
    EXPECT_EQ(s.at("boxd_measurements_total{status=\"failed\"}"), 1);
    EXPECT_EQ(s.at("boxd_measurement_reasons_total{status=\"no_dim\",code=\"MULTIPLE_OBJECTS\"}"),
              1);
    EXPECT_EQ(s.at("boxd_measurement_reasons_total{status=\"failed\",code=\"TURNTABLE_ERROR\"}"),
              1);
    EXPECT_EQ(s.at("boxd_device_faults_total{device=\"turntable\"}"), 1);
    EXPECT_EQ(s.at("boxd_device_faults_total{device=\"camera\"}"), 1);
    EXPECT_EQ(s.at("boxd_device_faults_total{device=\"scale\"}"), 2);
    // Cycle 0.5, 2.8, 3.0, 4.1 s: cumulative counts at each bound.
    EXPECT_EQ(s.at("boxd_measurement_cycle_seconds_bucket{le=\"0.25\"}"), 0);
    EXPECT_EQ(s.at("boxd_measurement_cycle_seconds_bucket{le=\"0.5\"}"), 1);
    EXPECT_EQ(s.at("boxd_measurement_cycle_seconds_bucket{le=\"3\"}"), 3);
    EXPECT_EQ(s.at("boxd_measurement_cycle_seconds_bucket{le=\"5\"}"), 4);
    EXPECT_EQ(s.at("boxd_measurement_cycle_seconds_bucket{le=\"+Inf\"}"), 4);
    EXPECT_EQ(s.at("boxd_measurement_cycle_seconds_count"), 4);
    EXPECT_NEAR(s.at("boxd_measurement_cycle_seconds_sum"), 10.4, 1e-9);
    EXPECT_EQ(s.at("boxd_measurement_processing_seconds_bucket{le=\"0.1\"}"), 2);
    EXPECT_EQ(s.at("boxd_measurement_processing_seconds_bucket{le=\"0.15\"}"), 3);
    EXPECT_EQ(s.at("boxd_state{state=\"error\"}"), 1);
    EXPECT_EQ(s.at("boxd_state{state=\"idle\"}"), 0);
    EXPECT_EQ(s.at("boxd_calibrated"), 1);
    EXPECT_EQ(s.at("boxd_calibration_age_seconds"), 3600);
}

}  // namespace
}  // namespace boxd
