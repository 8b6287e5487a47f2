// Data files shared with LIGGGHTS 3.8: LIGGGHTS reads the data file Granary's
// write_data wrote and writes it back (its write_data prints 17 significant
// digits, as Granary's); Granary reads LIGGGHTS' file and, written again,
// gives Granary's first file byte for byte: ids, types, diameters,
// densities, positions, image flags, velocities and angular velocities
// survive both programs exactly. Skipped without LIGGGHTS.
#include <unistd.h>

#include <catch2/catch.hpp>
#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>

#include "core/engine.h"
#include "particles/particles.h"
#include "script_engine.h"
#include "skip.h"

namespace {

std::string read_text(const std::string& path) {
  std::ifstream in(path);
  std::stringstream s;
  s << in.rdbuf();
  return s.str();
}

}  // namespace

TEST_CASE("LIGGGHTS reads Granary's data file and writes back the same particles", "[data_file][liggghts]") {
  if (std::system("command -v liggghts > /dev/null 2>&1") != 0) {
    granary::test::skip("LIGGGHTS (package liggghts) not installed");
    return;
  }
  auto t = granary::test::temp_template("granary_data_");
  REQUIRE(mkdtemp(t.data()) != nullptr);
  const std::string dir = t.data();
  const std::vector<std::string> head = {"units si", "atom_style granular", "boundary p f f"};
  granary::test::ScriptEngine a;
  a.cmds(head);
  a.cmds({"region reg block 0 0.1 0 0.1 0 0.1 units box", "create_box 2 reg", "lattice sc 0.02",
          "region fill block 0.01 0.09 0.01 0.09 0.01 0.09 units box", "create_atoms 1 region fill",
          "set type 1 type/fraction 2 0.5 11", "set type 1 diameter 0.003 density 2500",
          "set type 2 diameter 0.005 density 1100", "velocity all set 0.1 -0.2 0.05",
          "displace_atoms all move 0.0731 0.0011 0.0013 units box"});
  auto& p = *a.e.particles;
  REQUIRE(p.nlocal == 64);
  for (int i = 0; i < p.nlocal; ++i)
    p.omega[i] = granary::Vec3(std::sin(p.id[i]), std::cos(0.5 * p.id[i]), 1e-3 * p.id[i]);
  a.cmd("write_data " + dir + "/granary.data");
  std::ofstream(dir + "/in.data") << "units si\natom_style granular\natom_modify map array\nboundary p f f\n"
                                     "newton off\ncommunicate single vel yes\nread_data granary.data\n"
                                     "write_data liggghts.data\n";
  const int rc =
      std::system(("cd '" + dir + "' && liggghts -in in.data -log none > liggghts.out 2>&1").c_str());
  INFO(read_text(dir + "/liggghts.out"));
  REQUIRE(rc == 0);
  REQUIRE(std::filesystem::exists(dir + "/liggghts.data"));
  granary::test::ScriptEngine b;
  b.cmds(head);
  b.cmd("read_data " + dir + "/liggghts.data");
  CHECK(b.p().natoms == 64);
  b.cmd("write_data " + dir + "/again.data");
  CHECK(read_text(dir + "/again.data") == read_text(dir + "/granary.data"));
  std::filesystem::remove_all(dir);
}
