// AravisCamera against Aravis' own simulated cameras: the in-process "Fake" interface (free-running) and
// arv-fake-gv-camera-0.8, a GigE Vision camera served on 127.0.0.1, killed for the camera that vanishes
// mid-session.
#include "capture/aravis_camera.h"

#include <fcntl.h>
#include <signal.h>
#include <sys/file.h>
#include <sys/wait.h>
#include <unistd.h>

#include <chrono>
#include <string>
#include <thread>

#include <gtest/gtest.h>

#include "capture/capture_test_util.h"

namespace selfcal::capture {
namespace {

using testing::Contains;

constexpr char kFakeGvCamera[] = "/usr/bin/arv-fake-gv-camera-0.8";

// arv-fake-gv-camera-0.8 on 127.0.0.1 (it serves only an address an interface has), stopped with the test.
// GVCP's port 3956 allows one such camera on the host: a lock file serialises the tests that start one, in
// this binary and in any other test run on the machine.
class FakeGvCamera {
 public:
  FakeGvCamera() {
    lock_fd_ = ::open("/tmp/selfcal-arv-fake-gv-camera.lock", O_RDWR | O_CREAT | O_CLOEXEC, 0666);
    if (lock_fd_ >= 0) ::flock(lock_fd_, LOCK_EX);
    pid_ = ::fork();
    if (pid_ == 0) {
      ::execl(kFakeGvCamera, kFakeGvCamera, "-i", address_.c_str(), static_cast<char*>(nullptr));
      ::_exit(127);
    }
  }
  ~FakeGvCamera() {
    Kill();
    if (lock_fd_ >= 0) ::close(lock_fd_);  // releases the lock
  }
  const std::string& address() const { return address_; }
  void Kill() {
    if (pid_ > 0) {
      ::kill(pid_, SIGKILL);
      ::waitpid(pid_, nullptr, 0);
    }
    pid_ = -1;
  }

 private:
  std::string address_ = "127.0.0.1";
  pid_t pid_ = -1;
  int lock_fd_ = -1;
};

bool HaveFakeGvCamera() { return ::access(kFakeGvCamera, X_OK) == 0; }

// Open, retried while the fake camera process starts (it answers within a fraction of a second).
Status OpenWhenUp(AravisCamera* camera) {
  Status s;
  for (int attempt = 0; attempt < 20; ++attempt) {
    s = camera->Open();
    if (s.ok() || CaptureErrorOf(s) != CaptureError::kDeviceMissing) return s;
    std::this_thread::sleep_for(std::chrono::milliseconds(150));
  }
  return s;
}

AravisOptions InProcessFake() {
  AravisOptions options;
  options.camera_id = "Fake_1";
  options.fake_interface = true;
  options.check_frames = false;  // the fake's test pattern is a gradient, not a scene
  return options;
}

TEST(AravisFake, OpensLocksExposureAndGainAndGrabsAFrameExposedAfterTheSettle) {
  AravisOptions options = InProcessFake();
  options.exposure_s = 0.004;
  options.gain_db = 2;
  AravisCamera camera(options);
  ASSERT_TRUE(camera.Open().ok()) << camera.Open().message();
  EXPECT_TRUE(Contains(camera.identity(), "Aravis Fake")) << camera.identity();
  bool exposure_locked = false, gain_auto_off = false, gain_set = false;
  for (const AravisControlReport& c : camera.controls()) {
    if (c.name == "exposure_s") exposure_locked = c.as_requested && std::abs(c.value - 0.004) < 1e-6;
    if (c.name == "gain_auto") gain_auto_off = c.supported && c.as_requested;
    if (c.name == "gain_db") gain_set = c.as_requested && std::abs(c.value - 2) < 1e-6;
  }
  EXPECT_TRUE(exposure_locked) << camera.Describe();
  EXPECT_TRUE(gain_auto_off) << camera.Describe();
  EXPECT_TRUE(gain_set) << camera.Describe();
  EXPECT_TRUE(Contains(camera.Describe(), "exposure_s: locked (value 0.004)")) << camera.Describe();
  // The in-process fake lists a software trigger but runs free: found at Open, and treated as free-running.
  EXPECT_FALSE(camera.triggered()) << camera.Describe();
  for (int pose = 0; pose < 3; ++pose) {
    const double settled = MonotonicNowS() + 0.15;  // the arm settles 150 ms from now
    Result<Frame> frame = camera.Grab(settled, 2.0);
    ASSERT_TRUE(frame.ok()) << frame.status().message();
    EXPECT_GE(frame->exposure_time_s, settled);
    EXPECT_LE(frame->exposure_time_s, MonotonicNowS());
    EXPECT_EQ(frame->image.getWidth(), 512u);
    EXPECT_EQ(frame->image.getHeight(), 512u);
    EXPECT_EQ(frame->sequence, pose + 1);  // the test frame of Open was 0
  }
  EXPECT_GT(camera.stale_frames_discarded(), 0) << "frames exposed before the settle were handed out";
  camera.Close();
  camera.Close();
}

TEST(AravisFake, RegionAskedForAndRefusedWithWhatTheCameraOffers) {
  AravisOptions options = InProcessFake();
  options.width_px = 256;
  options.height_px = 128;
  AravisCamera camera(options);
  ASSERT_TRUE(camera.Open().ok());
  Result<Frame> frame = camera.Grab(MonotonicNowS(), 2.0);
  ASSERT_TRUE(frame.ok()) << frame.status().message();
  EXPECT_EQ(frame->image.getWidth(), 256u);
  EXPECT_EQ(frame->image.getHeight(), 128u);
  options.width_px = options.height_px = 5000;
  AravisCamera too_large(options);
  const Status open = too_large.Open();
  EXPECT_EQ(CaptureErrorOf(open), CaptureError::kFormatMismatch) << open.message();
  EXPECT_TRUE(Contains(open.message(), "Aravis camera Fake_1 (Aravis Fake 1): asked for 5000x5000")) << open.message();
  EXPECT_TRUE(Contains(open.message(), "the camera has 512x512; it offers 1x1 to 2048x2048 in steps of 1x1")) << open.message();
}

TEST(AravisFake, MissingCameraNamesWhatWasFound) {
  AravisOptions options = InProcessFake();
  options.camera_id = "Basler-acA1920-40gm-99999999";
  AravisCamera camera(options);
  const Status open = camera.Open();
  EXPECT_EQ(CaptureErrorOf(open), CaptureError::kDeviceMissing);
  EXPECT_EQ(open.code(), ErrorCode::kHardware);
  EXPECT_TRUE(Contains(open.message(), "Aravis camera Basler-acA1920-40gm-99999999 not found")) << open.message();
  EXPECT_TRUE(Contains(open.message(), "cameras found: ")) << open.message();
  EXPECT_TRUE(Contains(open.message(), "Fake_1")) << open.message();
  EXPECT_FALSE(camera.Grab(0, 0.1).ok());
}

TEST(AravisFake, OptionsRefusedBeforeAnyCameraIsTouched) {
  AravisOptions options = InProcessFake();
  options.width_px = 640;  // without a height
  options.num_buffers = 1;
  const std::string problems = options.Validate();
  EXPECT_TRUE(Contains(problems, "image size 640x0")) << problems;
  EXPECT_TRUE(Contains(problems, "num_buffers = 1")) << problems;
  AravisCamera camera(options);
  EXPECT_EQ(camera.Open().code(), ErrorCode::kInvalidInput);
}

TEST(AravisGvFake, SoftwareTriggerGivesTheFrameOfTheSettleAndATimeoutWhenTheSettleComesTooLate) {
  if (!HaveFakeGvCamera()) GTEST_SKIP() << kFakeGvCamera << " missing (Debian: aravis-tools)";
  FakeGvCamera fake;
  AravisOptions options;
  options.camera_id = fake.address();
  options.check_frames = false;
  options.exposure_s = 0.002;
  AravisCamera camera(options);
  ASSERT_TRUE(OpenWhenUp(&camera).ok()) << camera.Describe();
  EXPECT_TRUE(camera.triggered()) << camera.Describe();
  EXPECT_TRUE(Contains(camera.Describe(), "software trigger")) << camera.Describe();
  const double settled = MonotonicNowS() + 0.2;
  Result<Frame> frame = camera.Grab(settled, 2.0);
  ASSERT_TRUE(frame.ok()) << frame.status().message();
  EXPECT_GE(frame->exposure_time_s, settled);
  EXPECT_GE(MonotonicNowS(), settled);
  // A settle beyond the timeout: kTimeout after the timeout, not a frame and not a hang.
  const double asked = MonotonicNowS();
  Result<Frame> late = camera.Grab(asked + 5.0, 0.3);
  EXPECT_EQ(CaptureErrorOf(late.status()), CaptureError::kTimeout) << late.status().message();
  EXPECT_GE(MonotonicNowS() - asked, 0.3);
  EXPECT_LT(MonotonicNowS() - asked, 1.5);  // the timeout and one register read to tell it from a lost camera
  EXPECT_TRUE(camera.Grab(MonotonicNowS(), 2.0).ok()) << "a timeout is not a lost camera";
}

TEST(AravisGvFake, ACameraThatVanishesMidSessionIsDisconnectedAndFramesTakenStayValid) {
  if (!HaveFakeGvCamera()) GTEST_SKIP() << kFakeGvCamera << " missing (Debian: aravis-tools)";
  FakeGvCamera fake;
  AravisOptions options;
  options.camera_id = fake.address();
  options.check_frames = false;
  AravisCamera camera(options);
  ASSERT_TRUE(OpenWhenUp(&camera).ok()) << camera.Describe();
  Result<Frame> before = camera.Grab(MonotonicNowS(), 2.0);
  ASSERT_TRUE(before.ok()) << before.status().message();
  const vpImage<unsigned char> copy = before->image;
  fake.Kill();
  const double asked = MonotonicNowS();
  Result<Frame> after = camera.Grab(asked, 2.0);
  ASSERT_FALSE(after.ok());
  EXPECT_EQ(CaptureErrorOf(after.status()), CaptureError::kDisconnected) << after.status().message();
  EXPECT_TRUE(Contains(after.status().message(), fake.address())) << after.status().message();
  EXPECT_TRUE(Contains(after.status().message(), "samples already captured stay valid")) << after.status().message();
  EXPECT_LT(MonotonicNowS() - asked, 10.0);
  // Sticky: the next grab says so at once, without waiting for the camera again.
  const double again = MonotonicNowS();
  EXPECT_EQ(CaptureErrorOf(camera.Grab(again, 2.0).status()), CaptureError::kDisconnected);
  EXPECT_LT(MonotonicNowS() - again, 0.1);
  EXPECT_TRUE(testing::SameImage(before->image, copy));
  camera.Close();
}

TEST(AravisGvFake, AFreeRunningCameraThatVanishesIsDisconnectedNotATimeout) {
  if (!HaveFakeGvCamera()) GTEST_SKIP() << kFakeGvCamera << " missing (Debian: aravis-tools)";
  FakeGvCamera fake;
  AravisOptions options;
  options.camera_id = fake.address();
  options.software_trigger = false;
  options.check_frames = false;
  AravisCamera camera(options);
  ASSERT_TRUE(OpenWhenUp(&camera).ok()) << camera.Describe();
  EXPECT_FALSE(camera.triggered());
  const double settled = MonotonicNowS() + 0.1;
  Result<Frame> frame = camera.Grab(settled, 3.0);
  ASSERT_TRUE(frame.ok()) << frame.status().message();
  EXPECT_GE(frame->exposure_time_s, settled);
  fake.Kill();
  Result<Frame> after = camera.Grab(MonotonicNowS(), 1.0);
  EXPECT_EQ(CaptureErrorOf(after.status()), CaptureError::kDisconnected) << after.status().message();
}

}  // namespace
}  // namespace selfcal::capture
