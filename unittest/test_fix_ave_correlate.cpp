// fix ave/correlate:
// - against LIGGGHTS 3.8 (unittest/scripts/ave_correlate, references
//   unittest/reference/ave_correlate_*.liggghts.txt): three functions of the
//   step, types full, lower, upper and auto/lower, ave one and running: every
//   number of the output blocks equal to the 6 digits printed (the header's
//   third line differs: LIGGGHTS 3.8 names only some of the pairs there);
// - analytic: constants a = 2, b = 3 give C_ij = V_i V_j for every delay, in
//   LAMMPS' column order for auto/upper and auto/lower; a value that changes sign at every sample gives C(k)
//   = (-1)^k; the counts of the delays with ave one and running; prefactor; overwrite;
// - input errors.
#include <catch2/catch.hpp>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>
#include <vector>

#include "core/engine.h"
#include "core/input.h"
#include "script_engine.h"

namespace {

namespace fs = std::filesystem;
using Catch::Matchers::Contains;

// the lines of a file after the three header lines, split into numbers
std::vector<std::vector<double>> blocks(const fs::path& file) {
  std::ifstream in(file);
  REQUIRE(in.good());
  std::vector<std::vector<double>> rows;
  std::string line;
  int header = 0;
  while (std::getline(in, line)) {
    if (header < 3 && line.rfind("#", 0) == 0) {
      ++header;
      continue;
    }
    std::istringstream ls(line);
    std::vector<double> r;
    double v;
    while (ls >> v)
      r.push_back(v);
    rows.push_back(r);
  }
  return rows;
}

std::vector<std::string> box() {
  return {"atom_style granular",
          "atom_modify map array",
          "boundary f f f",
          "units si",
          "region d block 0 1 0 1 0 1 units box",
          "create_box 1 d",
          "timestep 1e-3"};
}

}  // namespace

TEST_CASE(
    "fix ave/correlate matches LIGGGHTS 3.8 for types full, lower, upper, auto/lower and ave one, running",
    "[fix][ave]") {
  const fs::path dir = fs::path(GRANARY_SOURCE_DIR) / "unittest/scripts/ave_correlate";
  for (const auto& [type, ave] : std::vector<std::pair<std::string, std::string>>{
           {"full", "one"}, {"lower", "running"}, {"upper", "one"}, {"auto/lower", "running"}}) {
    std::string name = type + "_" + ave;
    for (char& ch : name)
      if (ch == '/') ch = '_';
    granary::test::ScriptEngine s;
    s.cmd("variable type index " + type);
    s.cmd("variable ave index " + ave);
    s.cmd("variable name index " + name);
    s.e.input->file((dir / "in.ave_correlate").string());
    const auto mine = blocks("ac." + name + ".txt");
    const auto ref =
        blocks(fs::path(GRANARY_SOURCE_DIR) / ("unittest/reference/ave_correlate_" + name + ".liggghts.txt"));
    REQUIRE(ref.size() == 20);  // 4 outputs of 1 + 4 lines
    REQUIRE(mine.size() == ref.size());
    for (std::size_t r = 0; r < ref.size(); ++r) {
      REQUIRE(mine[r].size() == ref[r].size());
      for (std::size_t c = 0; c < ref[r].size(); ++c) {
        INFO(name << ": line " << r << " column " << c);
        CHECK(mine[r][c] == Approx(ref[r][c]).epsilon(1e-5).margin(1e-300));
      }
    }
  }
}

TEST_CASE("fix ave/correlate: constant and alternating values, counts, prefactor, overwrite", "[fix][ave]") {
  granary::test::ScriptEngine s;
  s.cmds(box());
  // a = 2, b = 3 every step; c = +1 / -1 on alternate samples (Nevery 2)
  s.cmds({"variable a equal 2", "variable b equal 3", "variable c equal 1-2*(step%4==2)",
          "fix u all ave/correlate 2 3 10 v_a v_b type auto/upper file acu.txt",
          "fix l all ave/correlate 2 3 10 v_a v_b type auto/lower prefactor 0.5 file acl.txt",
          "fix alt all ave/correlate 2 3 10 v_c ave running file acr.txt overwrite", "run 20"});
  const auto u = blocks("acu.txt"), l = blocks("acl.txt");
  REQUIRE(u.size() == 12);  // outputs at 0, 10, 20
  REQUIRE(l.size() == 12);
  for (int out = 0; out < 3; ++out) {
    CHECK(u[4 * out][0] == 10.0 * out);
    CHECK(u[4 * out][1] == 3.0);
    for (int k = 0; k < 3; ++k) {
      const auto& ru = u[4 * out + 1 + k];
      const auto& rl = l[4 * out + 1 + k];
      INFO("output " << out << " delay " << k);
      CHECK(ru[0] == k + 1);
      CHECK(ru[1] == 2 * k);
      // ave one: step 0 alone; then 6 samples (the output step's sample starts the next window)
      const double count = out == 0 ? (k == 0 ? 1 : 0) : 6 - k;
      CHECK(ru[2] == count);
      if (count == 0) continue;
      // auto/upper: C11 C12 C22; auto/lower: C11 C21 C22, times 0.5
      CHECK(ru[3] == 4.0);
      CHECK(ru[4] == 6.0);
      CHECK(ru[5] == 9.0);
      CHECK(rl[3] == 2.0);
      CHECK(rl[4] == 3.0);
      CHECK(rl[5] == 4.5);
    }
  }
  // overwrite: only the last output (step 20, running: 11 samples); C(k) = (-1)^k
  const auto r = blocks("acr.txt");
  REQUIRE(r.size() == 4);
  CHECK(r[0][0] == 20.0);
  for (int k = 0; k < 3; ++k) {
    CHECK(r[1 + k][2] == 11 - k);
    CHECK(r[1 + k][3] == (k % 2 == 0 ? 1.0 : -1.0));
  }
}

TEST_CASE("fix ave/correlate input errors", "[fix][ave]") {
  granary::test::ScriptEngine s;
  s.cmds(box());
  s.cmd("variable a equal 2");
  const std::vector<std::pair<std::string, std::string>> cases = {
      {"2 3 9 v_a", "must be a multiple of Nevery"},
      {"0 3 10 v_a", "must be positive"},
      {"2 7 10 v_a", "(Nrepeat-1)*Nevery (12) must not exceed Nfreq"},
      {"2 3 10", "needs Nevery, Nrepeat, Nfreq and a value"},
      {"2 3 10 v_a type middle", "type must be auto, upper"},
      {"2 3 10 v_a type upper", "correlates nothing"},
      {"2 3 10 v_a ave window", "ave must be one or running"},
      {"2 3 10 v_a overwrite file x.txt", "overwrite needs ave running"},
      {"2 3 10 v_a bogus 1", "unknown fix ave/correlate keyword 'bogus'"},
  };
  for (const auto& [args, expect] : cases) {
    INFO(args);
    CHECK_THROWS_WITH(s.cmd("fix bad all ave/correlate " + args), Contains(expect));
  }
  s.cmds({"variable p atom x", "fix pa all ave/correlate 2 3 10 v_p"});
  CHECK_THROWS_WITH(s.cmd("run 10"), Contains("equal-style"));
}
