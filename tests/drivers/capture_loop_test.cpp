// The capture loop with real pieces: the simulated camera rendering the synthetic station at the
// angle reported by a ModbusTurntable driving an in-process TurntableSimulator over Modbus TCP
// on loopback (fault injection included).
#include "drivers/capture_loop.h"

#include <gtest/gtest.h>

#include <atomic>
#include <chrono>
#include <thread>

#include "drivers/modbus_client.h"
#include "drivers/sim/simulated_camera.h"
#include "drivers/sim/turntable_simulator.h"
#include "drivers/turntable.h"

namespace boxd {
namespace {

using std::chrono::milliseconds;

// A TurntableSimulator serving on a thread for the test's lifetime.
class SimulatorThread {
public:
    explicit SimulatorThread(TurntableSimulatorConfig config) : sim_(config) {
        const Status st = sim_.ListenTcp("127.0.0.1", 0);
        EXPECT_TRUE(st.ok()) << st.error().message;
        thread_ = std::thread([this] { served_ = sim_.Serve(stop_); });
    }
    ~SimulatorThread() {
        stop_.store(true);
        thread_.join();
    }
    int port() const { return sim_.port(); }

    // Returns a special register of the simulator read over a separate connection.
    int ReadRegister(int address) const {
        ModbusLinkConfig link;
        link.host = "127.0.0.1";
        link.port = port();
        ModbusClient client(link);
        auto regs = client.ReadRegisters(address, 1);
        EXPECT_TRUE(regs.ok()) << regs.error().message;
        return regs.ok() ? (*regs)[0] : -1;
    }

private:
    TurntableSimulator sim_;
    std::atomic<bool> stop_{false};
    Status served_ = OkStatus();
    std::thread thread_;
};

TurntableSimulatorConfig FastSimulator() {
    TurntableSimulatorConfig c;
    c.max_speed_dps = 720.0;
    c.settle_ms = 10;
    return c;
}

std::unique_ptr<Turntable> Connect(int port, double speed_dps = 720.0) {
    TurntableConfig c;
    c.driver = "modbus-tcp";
    c.host = "127.0.0.1";
    c.port = port;
    c.speed_dps = speed_dps;
    c.move_timeout_ms = 20000;
    auto table = MakeTurntable(c);
    EXPECT_TRUE(table.ok()) << table.error().message;
    return table.ok() ? std::move(table).value() : nullptr;
}

// A small, quick-to-render simulated camera looking at the default box.
SimulatedCameraConfig SmallCamera() {
    SimulatedCameraConfig c;
    c.station.camera.width = 160;
    c.station.camera.height = 120;
    c.station.camera.fx = c.station.camera.fy = 142.5;
    c.station.camera.cx = 79.5;
    c.station.camera.cy = 59.5;
    c.station.seed = 11;
    return c;
}

AngleSource AngleOf(Turntable& table) {
    return [&table] { return table.CurrentAngleDeg(); };
}

// A fast simulated table served on a thread, the small simulated camera looking at it, and the
// station calibration its scene records.
struct Rig {
    explicit Rig(double speed_dps = 720.0)
        : table(Connect(sim.port(), speed_dps)), camera(SmallCamera(), [this]() -> Result<double> {
              if (!table) return Error{ErrorCode::kTurntableError, "no table"};
              return table->CurrentAngleDeg();
          }) {
        EXPECT_TRUE(camera.Open().ok());
        station.calibration = camera.Scene().recorded_calibration;
    }
    SimulatorThread sim{FastSimulator()};
    std::unique_ptr<Turntable> table;
    SimulatedCamera camera;
    CaptureStation station;
};

CaptureConfig QuickCapture(int poses) {
    CaptureConfig c;
    c.poses = poses;
    c.frames_per_pose = 2;
    c.drop_frames = 1;
    c.settle_ms = 0;
    c.grab_timeout_ms = 1000;
    return c;
}

TEST(CaptureLoop, CapturesEveryPoseWithRawFrames) {
    Rig rig;
    ASSERT_TRUE(rig.table);
    auto& [sim, table, camera, station] = rig;
    std::vector<std::pair<int, int>> progress;
    std::vector<std::size_t> handed_over;
    CaptureCallbacks cb;
    cb.on_progress = [&](int k, int n) { progress.emplace_back(k, n); };
    cb.on_pose = [&](std::size_t i, const SessionPose& pose) {
        EXPECT_EQ(pose.frames.size(), 2u);
        handed_over.push_back(i);
    };
    auto session = CaptureSession(*table, camera, QuickCapture(3), station, cb);
    ASSERT_TRUE(session.ok()) << session.error().message;

    EXPECT_EQ(session->source, "simulated");
    EXPECT_EQ(session->camera.width, 160);
    EXPECT_TRUE(session->calibration.table_center_m.isApprox(station.calibration.table_center_m));
    ASSERT_EQ(session->poses.size(), 3u);
    const double expected[] = {0.0, 120.0, 240.0};
    for (std::size_t i = 0; i < 3; ++i) {
        EXPECT_DOUBLE_EQ(session->poses[i].angle_deg, expected[i]);
        ASSERT_EQ(session->poses[i].frames.size(), 2u);
        EXPECT_EQ(session->poses[i].frame_paths[1], SessionFramePath(i, 1));
        EXPECT_EQ(session->poses[i].frames[0].width, 160);
    }
    // Views of a turned box differ; two frames of one pose differ only by noise.
    const auto& a = session->poses[0].frames[0].pixels;
    const auto& b = session->poses[1].frames[0].pixels;
    EXPECT_NE(a, b);
    EXPECT_EQ(handed_over, (std::vector<std::size_t>{0, 1, 2}));
    ASSERT_EQ(progress.size(), 4u);
    EXPECT_EQ(progress.front(), std::make_pair(0, 3));
    EXPECT_EQ(progress.back(), std::make_pair(3, 3));
    auto angle = table->CurrentAngleDeg();
    ASSERT_TRUE(angle.ok());
    EXPECT_NEAR(*angle, 240.0, 0.5);
}

TEST(CaptureLoop, AlternateSweepsStartWhereTheTableStandsAndTurnBack) {
    Rig rig;
    ASSERT_TRUE(rig.table);
    auto& [sim, table, camera, station] = rig;
    CaptureConfig config = QuickCapture(4);
    ASSERT_EQ(config.sweep, "alternate");

    // Not homed yet: the first sweep starts at home and turns forwards.
    auto first = CaptureSession(*table, camera, config, station);
    ASSERT_TRUE(first.ok()) << first.error().message;
    std::vector<double> angles;
    for (const auto& p : first->poses) angles.push_back(p.angle_deg);
    EXPECT_EQ(angles, (std::vector<double>{0.0, 90.0, 180.0, 270.0}));
    EXPECT_NEAR(*table->CurrentAngleDeg(), 270.0, 0.5);

    // The next parcel: from 270 back to 0, no turn to the start first.
    auto second = CaptureSession(*table, camera, config, station);
    ASSERT_TRUE(second.ok()) << second.error().message;
    angles.clear();
    for (const auto& p : second->poses) angles.push_back(p.angle_deg);
    EXPECT_EQ(angles, (std::vector<double>{0.0, -90.0, -180.0, -270.0}));
    EXPECT_NEAR(*table->CurrentAngleDeg(), 0.0, 0.5);

    // from_zero turns back to 0 and sweeps forwards every time.
    config.sweep = "from_zero";
    ASSERT_TRUE(table->MoveTo(180.0).ok());
    auto fixed = CaptureSession(*table, camera, config, station);
    ASSERT_TRUE(fixed.ok()) << fixed.error().message;
    EXPECT_DOUBLE_EQ(fixed->poses[1].angle_deg, 90.0);
    EXPECT_NEAR(*table->CurrentAngleDeg(), 270.0, 0.5);
}

TEST(CaptureLoop, CancellationStopsTheTableMidMove) {
    SimulatorThread sim(FastSimulator());
    auto table = Connect(sim.port(), 30.0);  // 0 -> 180 takes 6 s at 30 °/s
    ASSERT_TRUE(table);
    SimulatedCamera camera(SmallCamera(), AngleOf(*table));
    ASSERT_TRUE(camera.Open().ok());

    std::atomic<bool> cancel{false};
    std::thread canceller;
    CaptureCallbacks cb;
    cb.cancel = &cancel;
    cb.on_progress = [&](int k, int) {
        if (k == 1) {
            canceller = std::thread([&] {
                std::this_thread::sleep_for(milliseconds(500));
                cancel.store(true);
            });
        }
    };
    const int stops_before = sim.ReadRegister(kSimStopCountRegister);
    const auto start = std::chrono::steady_clock::now();
    auto session = CaptureSession(*table, camera, QuickCapture(2), CaptureStation{}, cb);
    const auto took = std::chrono::steady_clock::now() - start;
    canceller.join();

    ASSERT_FALSE(session.ok());
    EXPECT_EQ(session.error().code, ErrorCode::kCancelled);
    EXPECT_NE(session.error().message.find("pose 2 of 2"), std::string::npos)
        << session.error().message;
    EXPECT_LT(took, std::chrono::seconds(4));  // did not wait for the 6 s move
    EXPECT_GT(sim.ReadRegister(kSimStopCountRegister), stops_before);
    auto state = table->State();
    ASSERT_TRUE(state.ok()) << state.error().message;
    EXPECT_FALSE(state->moving);
    EXPECT_LT(state->angle_deg, 170.0);
}

TEST(CaptureLoop, FaultingTurntableGivesTurntableError) {
    TurntableSimulatorConfig sc = FastSimulator();
    sc.fault = SimulatedFault::kStall;
    sc.fault_after_moves = 1;  // the first pose move succeeds, a later one stalls
    SimulatorThread sim(sc);
    auto table = Connect(sim.port());
    ASSERT_TRUE(table);
    SimulatedCamera camera(SmallCamera(), AngleOf(*table));
    ASSERT_TRUE(camera.Open().ok());

    auto session = CaptureSession(*table, camera, QuickCapture(4), CaptureStation{});
    ASSERT_FALSE(session.ok());
    EXPECT_EQ(session.error().code, ErrorCode::kTurntableError);
    EXPECT_NE(session.error().message.find("pose"), std::string::npos) << session.error().message;
    auto state = table->State();
    ASSERT_TRUE(state.ok());
    EXPECT_FALSE(state->moving);
}

TEST(CaptureLoop, CameraErrorGivesCameraErrorAndStopsTheTable) {
    SimulatorThread sim(FastSimulator());
    auto table = Connect(sim.port());
    ASSERT_TRUE(table);
    SimulatedCameraConfig slow = SmallCamera();
    slow.frame_interval_ms = 200;  // slower than the grab timeout below
    SimulatedCamera camera(slow, AngleOf(*table));
    ASSERT_TRUE(camera.Open().ok());

    CaptureConfig capture = QuickCapture(3);
    capture.grab_timeout_ms = 50;
    const int stops_before = sim.ReadRegister(kSimStopCountRegister);
    auto session = CaptureSession(*table, camera, capture, CaptureStation{});
    ASSERT_FALSE(session.ok());
    EXPECT_EQ(session.error().code, ErrorCode::kCameraError);
    EXPECT_NE(session.error().message.find("no depth frame within 50 ms"), std::string::npos)
        << session.error().message;
    EXPECT_GT(sim.ReadRegister(kSimStopCountRegister), stops_before);
}

TEST(CaptureLoop, CameraThatLostTheTableGivesCameraError) {
    SimulatorThread sim(FastSimulator());
    auto table = Connect(sim.port());
    ASSERT_TRUE(table);
    // The camera's angle source fails like a turntable link that went away.
    SimulatedCamera camera(SmallCamera(), [] {
        return Result<double>(Error{ErrorCode::kTurntableError, "link down"});
    });
    ASSERT_TRUE(camera.Open().ok());
    auto session = CaptureSession(*table, camera, QuickCapture(2), CaptureStation{});
    ASSERT_FALSE(session.ok());
    EXPECT_EQ(session.error().code, ErrorCode::kCameraError);
    EXPECT_NE(session.error().message.find("link down"), std::string::npos);
}

TEST(CaptureConfig, ValidateNamesTheField) {
    {
        CaptureConfig c;
        c.sweep = "zigzag";
        ASSERT_FALSE(c.Validate());
        EXPECT_NE(c.Validate().error().message.find("capture.sweep"), std::string::npos);
    }
    CaptureConfig c;
    c.frames_per_pose = 0;
    auto st = c.Validate();
    ASSERT_FALSE(st.ok());
    EXPECT_NE(st.error().message.find("capture.frames_per_pose"), std::string::npos);
    c = CaptureConfig{};
    c.angles_deg = {0.0, std::nan("")};
    st = c.Validate();
    ASSERT_FALSE(st.ok());
    EXPECT_NE(st.error().message.find("capture.angles_deg[1]"), std::string::npos);
    c = CaptureConfig{};
    c.poses = 4;
    EXPECT_EQ(c.Angles(), (std::vector<double>{0.0, 90.0, 180.0, 270.0}));
    c = CaptureConfig{};
    c.order = "spiral";
    ASSERT_FALSE(c.Validate());
    EXPECT_NE(c.Validate().error().message.find("capture.order"), std::string::npos);
    c = CaptureConfig{};
    c.target_uncertainty_m = -0.001;
    ASSERT_FALSE(c.Validate());
    EXPECT_NE(c.Validate().error().message.find("capture.target_uncertainty_m"), std::string::npos);
}

TEST(CaptureConfig, CoverageOrderSurroundsTheObjectFirstThenComesBack) {
    CaptureConfig c;
    c.poses = 18;
    ASSERT_EQ(c.order, "coverage");
    EXPECT_EQ(c.Angles(), (std::vector<double>{0, 60, 120, 180, 240, 300, 340, 320, 280, 260, 220,
                                               200, 160, 140, 100, 80, 40, 20}));
    c.poses = 36;  // every 6th first: still 60 degrees apart
    const std::vector<double> a36 = c.Angles();
    ASSERT_EQ(a36.size(), 36u);
    EXPECT_EQ(std::vector<double>(a36.begin(), a36.begin() + 7),
              (std::vector<double>{0, 60, 120, 180, 240, 300, 350}));
    c.poses = 8;  // 45 degrees apart already: in order
    EXPECT_EQ(c.Angles(), (std::vector<double>{0, 45, 90, 135, 180, 225, 270, 315}));
    c.poses = 18;
    c.order = "sequential";
    EXPECT_EQ(c.Angles()[1], 20.0);
    c.angles_deg = {0, 200, 100};  // explicit angles keep their order
    c.order = "coverage";
    EXPECT_EQ(c.Angles(), (std::vector<double>{0, 200, 100}));
}

TEST(CaptureLoop, StopsWhenAskedAndTellsThePlanFirst) {
    Rig rig;
    ASSERT_TRUE(rig.table);
    auto& [sim, table, camera, station] = rig;
    CaptureConfig config = QuickCapture(12);  // coverage: 0, 60, ... 300, then 330, 270, ...
    std::vector<double> plan;
    std::vector<int> asked;
    CaptureCallbacks cb;
    cb.on_plan = [&](const std::vector<double>& angles) { plan = angles; };
    cb.stop = [&](int captured) {
        asked.push_back(captured);
        return captured == 6;
    };
    auto session = CaptureSession(*table, camera, config, station, cb);
    ASSERT_TRUE(session.ok()) << session.error().message;
    EXPECT_EQ(plan, (std::vector<double>{0, 60, 120, 180, 240, 300, 330, 270, 210, 150, 90, 30}));
    ASSERT_EQ(session->poses.size(), 6u);
    EXPECT_DOUBLE_EQ(session->poses[5].angle_deg, 300.0);
    EXPECT_EQ(asked, (std::vector<int>{1, 2, 3, 4, 5, 6}));
    EXPECT_NEAR(*table->CurrentAngleDeg(), 300.0, 0.5);  // it did not turn on

    // The next parcel starts where the table stands, with no move, and the plan turns back.
    cb.stop = nullptr;
    config.poses = 3;
    auto next = CaptureSession(*table, camera, config, station, cb);
    ASSERT_TRUE(next.ok()) << next.error().message;
    EXPECT_EQ(plan, (std::vector<double>{0, -120, -240}));
    EXPECT_NEAR(*table->CurrentAngleDeg(), 60.0, 0.5);
}

TEST(SimulatedCamera, AngleErrorIsPerPoseAndRepeatable) {
    SimulatedCameraConfig c = SmallCamera();
    c.station.angle_error_deg = 0.3;
    SimulatedCamera camera(c, [] { return Result<double>(0.0); });
    const double a = camera.TrueAngleRad(40.0);
    EXPECT_DOUBLE_EQ(a, camera.TrueAngleRad(40.0));
    EXPECT_NE(a, camera.TrueAngleRad(60.0) - (20.0 * M_PI / 180.0));
    EXPECT_NEAR(a, 40.0 * M_PI / 180.0, 1.5 * M_PI / 180.0);  // 5 sigma
    c.station.angle_error_deg = 0.0;
    SimulatedCamera exact(c, [] { return Result<double>(0.0); });
    EXPECT_DOUBLE_EQ(exact.TrueAngleRad(40.0), 40.0 * M_PI / 180.0);
}

}  // namespace
}  // namespace boxd
