// "Nothing lost" (issue 23): `quadlod simplify` killed at random moments by SIGINT, SIGTERM or
// SIGKILL leaves either no output or a complete one (the previous output, or this run's when it
// finished first), never a partial file; after SIGINT / SIGTERM no temporary file remains.
#include "quadlod/generators.h"
#include "quadlod/io.h"

#include "cli_runner.h"

#include <gtest/gtest.h>

#include <chrono>
#include <csignal>
#include <fstream>
#include <random>
#include <thread>
#include <sys/wait.h>
#include <unistd.h>

#if defined(__SANITIZE_ADDRESS__)
#define QUADLOD_TEST_ASAN 1
#elif defined(__has_feature)
#if __has_feature(address_sanitizer)
#define QUADLOD_TEST_ASAN 1
#endif
#endif

namespace quadlod {
namespace {

namespace fs = std::filesystem;

// A grid whose simplify runs a few hundred milliseconds to seconds: long enough to be killed at
// many moments; smaller under ASan, where the same run is ~10× slower (CI time).
#ifdef QUADLOD_TEST_ASAN
constexpr Index kGridSide = 64;
#else
constexpr Index kGridSide = 160;
#endif
using testing::slurp;

// Starts `quadlod -q simplify INPUT -o OUTPUT --ratio RATIO` with stdout/stderr on /dev/null.
pid_t start_simplify(const fs::path& input, const fs::path& output, const char* ratio) {
  const pid_t pid = ::fork();
  if (pid == 0) {
    std::freopen("/dev/null", "w", stdout);
    std::freopen("/dev/null", "w", stderr);
    ::execl(QUADLOD_CLI_PATH, QUADLOD_CLI_PATH, "-q", "simplify", input.c_str(), "-o", output.c_str(), "--ratio",
            ratio, static_cast<char*>(nullptr));
    ::_exit(127);
  }
  return pid;
}

int wait_for(pid_t pid) {
  int status = 0;
  ::waitpid(pid, &status, 0);
  return status;
}

std::vector<fs::path> temporaries(const fs::path& dir) {
  std::vector<fs::path> out;
  for (const auto& e : fs::directory_iterator(dir))
    if (e.path().filename().string().find(".tmp-") != std::string::npos) out.push_back(e.path());
  return out;
}

class Interrupt : public testing::ScratchDirTest {};

TEST_F(Interrupt, KilledSimplifyLeavesNoPartialOutputAndNoTempFiles) {
  const fs::path input = dir / "grid.obj";
  ASSERT_TRUE(write_mesh(make_grid(kGridSide, kGridSide), input).ok());
  // The two complete outputs a killed run may leave: the previous run's and its own.
  const fs::path out = dir / "out.obj";
  const auto t0 = std::chrono::steady_clock::now();
  ASSERT_EQ(wait_for(start_simplify(input, out, "0.3")), 0);
  const double run_seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  const std::string own = slurp(out);
  ASSERT_EQ(wait_for(start_simplify(input, out, "0.5")), 0);
  const std::string previous = slurp(out);
  ASSERT_NE(own, previous);

  std::mt19937 rng(23);
  // Moments over the whole run and a little beyond, so some kills land in or after the write.
  std::uniform_real_distribution<double> moment(0.0, 1.1 * run_seconds);
  int finished = 0, killed = 0;
  for (int trial = 0; trial < 24; ++trial) {
    const int signal_number = trial % 3 == 0 ? SIGINT : trial % 3 == 1 ? SIGTERM : SIGKILL;
    SCOPED_TRACE("trial " + std::to_string(trial) + ", signal " + std::to_string(signal_number));
    // Every fourth trial writes to a fresh path: then "no output" is the other correct answer.
    const bool fresh = trial % 4 == 3;
    const fs::path target = fresh ? dir / "fresh.obj" : out;
    if (fresh) fs::remove(target);
    const pid_t pid = start_simplify(input, target, "0.3");
    std::this_thread::sleep_for(std::chrono::duration<double>(moment(rng)));
    ::kill(pid, signal_number);
    const int status = wait_for(pid);
    if (WIFSIGNALED(status)) {
      ++killed;
      EXPECT_EQ(WTERMSIG(status), signal_number);
    } else {
      ++finished;
      EXPECT_EQ(WEXITSTATUS(status), 0);
    }
    if (fs::exists(target)) {
      const std::string now = slurp(target);
      EXPECT_TRUE(now == own || (!fresh && now == previous)) << "partial or foreign output, " << now.size() << " bytes";
    } else {
      EXPECT_TRUE(fresh) << "the previous output was lost";
    }
    const std::vector<fs::path> left = temporaries(dir);
    if (signal_number != SIGKILL) {
      EXPECT_TRUE(left.empty()) << left.front();
    }
    for (const fs::path& p : left) fs::remove(p);  // SIGKILL cannot be caught: its temp file may stay
    if (!fresh) {
      std::ofstream(out, std::ios::binary) << previous;  // the next trial starts from the previous output
    }
  }
  std::printf("interrupt: %d runs killed, %d finished first\n", killed, finished);
  EXPECT_GT(killed, 0);
}

// The moment that matters, hit on purpose: a signal while write_file_atomically() is writing
// (its temp file exists) removes the temp file and leaves the previous file as it was.
TEST_F(Interrupt, SignalDuringTheWriteRemovesTheTempFileAndKeepsThePreviousFile) {
  const fs::path target = dir / "big.obj";
  const std::string previous = "# the previous complete output\n";
  int hit = 0;
  for (int signal_number : {SIGINT, SIGTERM, SIGHUP}) {
    SCOPED_TRACE("signal " + std::to_string(signal_number));
    std::ofstream(target, std::ios::binary) << previous;
    const pid_t pid = ::fork();
    if (pid == 0) {
      install_interrupt_cleanup();
      const std::string contents(std::size_t{256} << 20, 'x');  // long enough to be caught writing
      ::_exit(write_file_atomically(target, contents).ok() ? 0 : 1);
    }
    // Wait for the temp file to appear (the child allocates first), then signal.
    const auto give_up = std::chrono::steady_clock::now() + std::chrono::seconds(60);
    while (temporaries(dir).empty() && std::chrono::steady_clock::now() < give_up) {
      int status = 0;
      if (::waitpid(pid, &status, WNOHANG) == pid) break;  // finished before we looked
      std::this_thread::sleep_for(std::chrono::microseconds(200));
    }
    ::kill(pid, signal_number);
    const int status = wait_for(pid);
    if (WIFSIGNALED(status)) {
      ++hit;
      EXPECT_EQ(WTERMSIG(status), signal_number);
      EXPECT_EQ(slurp(target), previous);
    } else {
      EXPECT_EQ(fs::file_size(target), std::size_t{256} << 20);  // it won the race: complete
    }
    EXPECT_TRUE(temporaries(dir).empty());
  }
  EXPECT_GT(hit, 0) << "no signal landed during a write";
}

}  // namespace
}  // namespace quadlod
