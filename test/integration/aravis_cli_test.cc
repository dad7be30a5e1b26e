// `name-dots` and `run` with Aravis' simulated cameras (--camera aravis:ID): the in-process "Fake_1" and
// arv-fake-gv-camera-0.8 on 127.0.0.1, the latter killed mid-session (the session halts with exit 4, the
// frames taken before are kept, and --resume continues once the camera is back). The simulated cameras show
// a test pattern without dots: frames are grabbed and the poses skipped for too few dots, which is what
// these tests need (the camera's path through the session, not a calibration).
#include <fcntl.h>
#include <signal.h>
#include <arpa/inet.h>
#include <netinet/in.h>
#include <sys/file.h>
#include <sys/socket.h>
#include <sys/wait.h>
#include <unistd.h>

#include <atomic>
#include <chrono>
#include <cstdio>
#include <filesystem>
#include <string>
#include <thread>
#include <vector>

#include <gtest/gtest.h>

#include "support/cli.h"

namespace selfcal {
namespace {

using testing::FreshDir;
using testing::ReadFile;
using testing::RunSelfcal;

constexpr char kFakeGvCamera[] = "/usr/bin/arv-fake-gv-camera-0.8";

bool Has(const std::string& text, const std::string& part) { return text.find(part) != std::string::npos; }

pid_t Spawn(const std::vector<std::string>& args, FILE** out = nullptr) {
  int fds[2];
  if (out != nullptr && ::pipe(fds) != 0) return -1;
  const pid_t pid = ::fork();
  if (pid == 0) {
    if (out != nullptr) ::dup2(fds[1], 1);
    if (::chdir(SELFCAL_SOURCE_DIR) != 0) ::_exit(126);
    std::vector<char*> argv;
    for (const std::string& a : args) argv.push_back(const_cast<char*>(a.c_str()));
    argv.push_back(nullptr);
    ::execv(argv[0], argv.data());
    ::_exit(127);
  }
  if (out != nullptr) {
    ::close(fds[1]);
    *out = ::fdopen(fds[0], "r");
  }
  return pid;
}

void Stop(pid_t* pid) {
  if (*pid > 0) {
    ::kill(*pid, SIGKILL);
    ::waitpid(*pid, nullptr, 0);
  }
  *pid = -1;
}

// Waits (up to 10 s) until the fake camera holds GVCP's port 3956 on 127.0.0.1, i.e. it answers discovery;
// a fixed half second was too short on a loaded machine. True when it does.
bool WaitForFakeCamera() {
  for (int attempt = 0; attempt < 100; ++attempt) {
    const int fd = ::socket(AF_INET, SOCK_DGRAM | SOCK_CLOEXEC, 0);
    if (fd < 0) return false;
    sockaddr_in address{};
    address.sin_family = AF_INET;
    address.sin_port = htons(3956);
    address.sin_addr.s_addr = htonl(INADDR_LOOPBACK);
    const bool taken = ::bind(fd, reinterpret_cast<const sockaddr*>(&address), sizeof(address)) != 0;
    ::close(fd);
    if (taken) return true;
    std::this_thread::sleep_for(std::chrono::milliseconds(100));
  }
  return false;
}

// setup.json for the fake cameras' 512x512 frames.
std::string WriteSetup(const std::filesystem::path& dir) {
  const std::string path = (dir / "setup.json").string();
  testing::WriteFile(path, R"({
  "format": "selfcal-session-setup",
  "version": 1,
  "camera": {"width_px": 512, "height_px": 512, "fx_px": 700.0, "cx_px": 255.5, "cy_px": 255.5, "mu": 1.0, "k1": 0.0},
  "pixel_noise_px": 0.1,
  "yardsticks": [],
  "check_distances": []
}
)");
  return path;
}

TEST(AravisCli, NameDotsGrabsAFrameFromAravisFakeCamera) {
  const std::filesystem::path dir = FreshDir("aravis_cli", "name_dots");
  const std::string setup = (dir / "setup.json").string(), png = (dir / "named.png").string();
  std::string output;
  EXPECT_EQ(RunSelfcal("name-dots --camera aravis:Fake_1 --exposure-ms 4 --setup " + setup + " --out " + png +
                           " --fx-px 700 --pixel-noise-px 0.1",
                       &output),
            3)
      << output;
  EXPECT_TRUE(Has(output, "camera: Aravis Fake_1 (Aravis Fake 1): 512x512 Mono8, free-running")) << output;
  EXPECT_TRUE(Has(output, "exposure_s: locked (value 0.004)")) << output;
  EXPECT_TRUE(Has(output, "no dot named")) << output;  // the fake's test pattern has none
  EXPECT_TRUE(std::filesystem::exists(png)) << "the annotated frame is saved for the operator";
  EXPECT_FALSE(std::filesystem::exists(setup));
}

TEST(AravisCli, CameraOptionsThatDoNotFitTheBackendAreRefused) {
  const std::filesystem::path dir = FreshDir("aravis_cli", "refusals");
  const std::string out = " --setup " + (dir / "s.json").string() + " --out " + (dir / "n.png").string();
  std::string output;
  EXPECT_EQ(RunSelfcal("name-dots --camera aravis --device /dev/video0" + out, &output), 2) << output;
  EXPECT_TRUE(Has(output, "give exactly one of --image FILE, --device DEVICE (a V4L2 camera) and --camera")) << output;
  EXPECT_EQ(RunSelfcal("name-dots --camera aravis:Fake_1 --camera-format MJPG" + out, &output), 2) << output;
  EXPECT_TRUE(Has(output, "--camera-format is a V4L2 option")) << output;
  EXPECT_EQ(RunSelfcal("name-dots --device /dev/video0 --gain-db 3" + out, &output), 2) << output;
  EXPECT_TRUE(Has(output, "--gain-db is an Aravis option")) << output;
  EXPECT_EQ(RunSelfcal("name-dots --camera aravis:Fake_1 --camera-width-px 4096 --camera-height-px 4096" + out, &output),
            4)
      << output;
  EXPECT_TRUE(Has(output, "asked for 4096x4096, the camera has 512x512; it offers 1x1 to 2048x2048")) << output;
  EXPECT_EQ(RunSelfcal("name-dots --camera gige" + out, &output), 2) << output;
  EXPECT_FALSE(std::filesystem::exists(dir / "n.png"));
}

// A network session with a GigE Vision camera that is unplugged after the second pose settled.
TEST(AravisCli, RunHaltsWhenTheGigECameraVanishesAndResumesWhenItIsBack) {
  if (::access(kFakeGvCamera, X_OK) != 0) GTEST_SKIP() << kFakeGvCamera << " missing (Debian: aravis-tools)";
  // GVCP's port 3956 on 127.0.0.1 takes one fake camera on the host: the capture tests take this lock too.
  const int lock = ::open("/tmp/selfcal-arv-fake-gv-camera.lock", O_RDWR | O_CREAT | O_CLOEXEC, 0666);
  if (lock >= 0) ::flock(lock, LOCK_EX);
  const std::filesystem::path dir = FreshDir("aravis_cli", "vanish");
  const std::string setup = WriteSetup(dir), plan = (dir / "plan.yaml").string(), session = (dir / "s").string();
  testing::WriteShortPlan(plan, 6, 4);
  FILE* robot_out = nullptr;
  pid_t robot = Spawn({SELFCAL_ROBOT_SIM, "--port", "0", "--robot", "config/robots/puma560.yaml", "--max-velocity-deg-s",
                       "200", "--initial-joints-deg", "33.1545", "19.3429", "-188.822", "75.3602", "43.4552", "-25.34"},
                      &robot_out);
  char line[256] = {0};
  int port = -1;
  if (robot_out != nullptr && std::fgets(line, sizeof(line), robot_out) != nullptr) {
    std::sscanf(line, "listening on 127.0.0.1:%d", &port);
  }
  ASSERT_GT(port, 0) << "selfcal-robot-sim did not print its port";
  pid_t camera = Spawn({kFakeGvCamera, "-i", "127.0.0.1"});
  ASSERT_TRUE(WaitForFakeCamera()) << kFakeGvCamera << " did not take GVCP's port";
  const std::string run = "run --session " + session + " --plan " + plan + " --backend network --address 127.0.0.1:" +
                          std::to_string(port) + " --camera aravis:127.0.0.1 --setup " + setup + " --live-view off";
  std::string output;
  std::atomic<int> code{-1};
  std::thread running([&] { code = RunSelfcal(run + " < /dev/null", &output); });
  // Unplug the camera once the second pose settled.
  while (code < 0 && !Has(ReadFile(session + "/journal.log"), R"("pose":1,"time_s")")) {
    std::this_thread::sleep_for(std::chrono::milliseconds(100));
  }
  Stop(&camera);
  running.join();
  EXPECT_EQ(code.load(), 4) << output;
  EXPECT_TRUE(Has(output, "camera_disconnected: Aravis camera 127.0.0.1 (Aravis Fake GV01)")) << output;
  EXPECT_TRUE(Has(output, "The robot was told to stop")) << output;
  const std::string journal = ReadFile(session + "/journal.log");
  EXPECT_TRUE(Has(journal, "\"reason\":\"camera_disconnected\"")) << journal;
  EXPECT_TRUE(std::filesystem::exists(session + "/images/rejected/p00_0.png")) << "the first pose's frame is kept";
  // The camera is back: the same command with --resume visits the rest.
  camera = Spawn({kFakeGvCamera, "-i", "127.0.0.1"});
  ASSERT_TRUE(WaitForFakeCamera()) << kFakeGvCamera << " did not take GVCP's port";
  EXPECT_EQ(RunSelfcal(run + " --resume < /dev/null", &output), 3) << output;  // too few samples: no dots
  EXPECT_TRUE(Has(output, "every pose was visited")) << output;
  Stop(&camera);
  Stop(&robot);
  if (lock >= 0) ::close(lock);
}

}  // namespace
}  // namespace selfcal
