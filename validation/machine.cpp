#include "validation/machine.hpp"

#include <algorithm>
#include <array>
#include <atomic>
#include <chrono>
#include <ctime>
#include <fstream>
#include <sstream>
#include <thread>
#include <vector>

namespace cairn::validation {

std::string utcNow() {
  const std::time_t t = std::chrono::system_clock::to_time_t(std::chrono::system_clock::now());
  std::tm tm{};
  gmtime_r(&t, &tm);
  char buf[64];
  std::strftime(buf, sizeof buf, "%Y-%m-%d %H:%M UTC", &tm);
  return buf;
}

MachineInfo currentMachine() {
  MachineInfo m;
  m.cpus = static_cast<int>(std::thread::hardware_concurrency());
  m.cpu_model = "unknown";
  std::ifstream f("/proc/cpuinfo");
  for (std::string line; std::getline(f, line);)
    if (line.rfind("model name", 0) == 0 && line.find(':') != std::string::npos) {
      const size_t at = line.find_first_not_of(" \t", line.find(':') + 1);
      if (at != std::string::npos) m.cpu_model = line.substr(at);
      break;
    }
  return m;
}

std::string loadAverage() {
  std::ifstream f("/proc/loadavg");
  std::string one, five, fifteen;
  if (!(f >> one >> five >> fifteen)) return "unknown";
  return one + " " + five + " " + fifteen;
}

namespace {

// Seconds one thread takes for a fixed amount of independent multiply-add
// work (a chain's latency is four cycles on current cores, two units
// start one each cycle: twelve chains keep both busy).
double multiplyAddSeconds() {
  constexpr long kRounds = 1L << 19;
  std::array<double, 12> a{};
  for (size_t k = 0; k < a.size(); ++k) a[k] = 1 + static_cast<double>(k) * 1e-3;
  const auto start = std::chrono::steady_clock::now();
  for (long i = 0; i < kRounds; ++i)
    for (double& x : a) x = x * 0.9999999 + 1e-7;
  const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  volatile double sink = 0;
  for (const double x : a) sink = sink + x;  // the chains' results are used
  return seconds;
}

}  // namespace

double coreShare(int threads) {
  if (threads < 2) return 1;
  double alone = 1e30, together = 1e30;
  for (int round = 0; round < 3; ++round) alone = std::min(alone, multiplyAddSeconds());
  for (int round = 0; round < 3; ++round) {
    std::atomic<int> ready{0};
    std::vector<double> took(static_cast<size_t>(threads));
    const auto run = [&](int t) {
      ready.fetch_add(1);
      while (ready.load() < threads) {
      }
      took[static_cast<size_t>(t)] = multiplyAddSeconds();
    };
    std::vector<std::thread> others;
    for (int t = 1; t < threads; ++t) others.emplace_back(run, t);
    run(0);
    for (std::thread& o : others) o.join();
    together = std::min(together, *std::max_element(took.begin(), took.end()));
  }
  return alone / together;
}

}  // namespace cairn::validation
