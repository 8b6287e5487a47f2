// examples/refill: a shortened refill cycle run as separate program
// invocations (in.fill, then in.refill twice), each reading the restart file
// the previous one wrote. Checks that every refill brings the particle count
// back to the target, that each discharge removes particles, and that step and
// simulated time continue across the chain.
#include <sys/wait.h>
#include <unistd.h>

#include <catch2/catch.hpp>
#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <map>
#include <sstream>
#include <string>
#include <vector>

namespace {

namespace fs = std::filesystem;

// The shortened study: a 12 mm container filled to 40 mm with 3 mm spheres
// (256 spheres at phi = 0.2), 3000 steps of settling, 2000 of discharge.
const double kR = 0.012, kH = 0.04, kD = 0.003, kPhi = 0.2, kDt = 1e-5;
const long long kSettle = 3000, kDischarge = 2000;
const std::string kVars =
    " -var R 0.012 -var H 0.04 -var settle 3000 -var discharge 2000 -var drain_every 200";

struct Stage {
  std::string what;  // FILL, DISCHARGE, RESTART, REFILL
  int cycle = 0;
  long long step = -1;
  double time = -1;
  long long atoms = -1;
};

std::string read_text(const std::string& file) {
  std::ifstream in(file);
  std::stringstream ss;
  ss << in.rdbuf();
  return ss.str();
}

// Run the program in `dir` with a clean environment; returns the exit status.
int run_program(const std::string& dir, const std::string& args, const std::string& out) {
  const std::string cmd = "cd \"" + dir + "\" && env -i PATH=\"$PATH\" HOME=\"$HOME\" " GRANARY_BINARY " " +
                          args + " -log none > " + out + " 2>&1 < /dev/null";
  const int rc = std::system(cmd.c_str());
  return WIFEXITED(rc) ? WEXITSTATUS(rc) : 128;
}

// The lines "WHAT [cycle] step S time T atoms N" the scripts print.
std::vector<Stage> stages(const std::string& text) {
  std::vector<Stage> out;
  std::istringstream in(text);
  std::string line;
  while (std::getline(in, line)) {
    std::istringstream ws(line);
    Stage s;
    ws >> s.what;
    if (s.what != "FILL" && s.what != "DISCHARGE" && s.what != "RESTART" && s.what != "REFILL") continue;
    std::string word;
    ws >> word;
    if (word != "step") {
      s.cycle = std::stoi(word);
      ws >> word;
    }
    if (word != "step") continue;
    ws >> s.step >> word >> s.time >> word >> s.atoms;
    if (ws) out.push_back(s);
  }
  return out;
}

}  // namespace

TEST_CASE("example refill: the fill/refill restart chain across program invocations", "[example][restart]") {
  const fs::path src = fs::path(GRANARY_SOURCE_DIR) / "examples" / "refill";
  const fs::path dir = fs::temp_directory_path() / ("granary_refill_" + std::to_string(::getpid()));
  fs::remove_all(dir);
  fs::create_directories(dir);
  for (const char* f : {"in.fill", "in.refill"})
    fs::copy_file(src / f, dir / f);

  const double vp = M_PI / 6 * kD * kD * kD;
  const double target = kPhi * M_PI * kR * kR * kH / vp;  // 256 spheres in the fill zone
  // insert/pack rounds the missing volume stochastically, and particles of the
  // bed that have not settled yet may lie above the fill zone: 3 %
  const double tol = 0.03 * target;

  // 1. fill, settle, discharge, write fill.restart
  REQUIRE(run_program(dir.string(), "-in in.fill" + kVars, "fill.out") == 0);
  const auto fill = stages(read_text((dir / "fill.out").string()));
  INFO(read_text((dir / "fill.out").string()));
  REQUIRE(fill.size() == 2);
  CHECK(fill[0].what == "FILL");
  CHECK(fill[0].step == kSettle);
  CHECK(std::fabs(fill[0].atoms - target) <= tol);
  CHECK(fill[1].what == "DISCHARGE");
  CHECK(fill[1].step == kSettle + kDischarge);
  CHECK(fill[1].atoms < fill[0].atoms);
  REQUIRE(fs::exists(dir / "fill.restart"));

  // 2. cycles 1 and 2 from fill.restart; 3. cycle 3 from refill_2.restart
  REQUIRE(run_program(dir.string(), "-in in.refill" + kVars + " -var first 1 -var last 2", "refill_a.out") ==
          0);
  REQUIRE(run_program(dir.string(),
                      "-in in.refill" + kVars + " -var restart_in refill_2.restart -var first 3 -var last 3",
                      "refill_b.out") == 0);
  auto chain = stages(read_text((dir / "refill_a.out").string()));
  const auto more = stages(read_text((dir / "refill_b.out").string()));
  INFO(read_text((dir / "refill_a.out").string()) << read_text((dir / "refill_b.out").string()));
  chain.insert(chain.end(), more.begin(), more.end());
  // RESTART, then REFILL k and DISCHARGE k for k = 1, 2; RESTART, REFILL 3, DISCHARGE 3
  REQUIRE(chain.size() == 8);

  Stage last = fill[1];
  int cycle = 0;
  for (const Stage& s : chain) {
    INFO(s.what << " " << s.cycle << " at step " << s.step);
    if (s.what == "RESTART") {
      // the state continues exactly where the previous invocation wrote it
      CHECK(s.step == last.step);
      CHECK(s.time == Approx(last.time).epsilon(1e-12));
      CHECK(s.atoms == last.atoms);
    } else if (s.what == "REFILL") {
      CHECK(s.cycle == ++cycle);
      CHECK(s.step == last.step + kSettle);
      CHECK(std::fabs(s.atoms - target) <= tol);  // back to the target
      CHECK(s.atoms > last.atoms);
    } else {
      REQUIRE(s.what == "DISCHARGE");
      CHECK(s.cycle == cycle);
      CHECK(s.step == last.step + kDischarge);
      CHECK(s.atoms < last.atoms);  // particles left through the opening
      CHECK(fs::exists(dir / ("refill_" + std::to_string(cycle) + ".restart")));
    }
    CHECK(s.time == Approx(s.step * kDt).epsilon(1e-9));
    last = s;
  }
  CHECK(cycle == 3);
  CHECK(last.step == 4 * (kSettle + kDischarge));
  fs::remove_all(dir);
}
