// compute region-phi gives the same value on any number of ranks: the engine
// on MPI_COMM_WORLD against one on MPI_COMM_SELF (a single rank).
#include <mpi.h>

#include <catch2/catch.hpp>
#include <cstdio>
#include <string>
#include <vector>

#include "script_engine.h"

namespace {

std::vector<std::string> scene() {
  std::vector<std::string> s = {"units si", "atom_style granular", "boundary p f f",
                                "region box block -0.01 0.01 -0.01 0.01 -0.01 0.01", "create_box 2 box"};
  // free spheres on a jittered lattice, two types and sizes
  for (int i = 0; i < 8; ++i)
    for (int j = 0; j < 6; ++j)
      for (int k = 0; k < 4; ++k) {
        char line[160];
        std::snprintf(line, sizeof line, "create_atoms %d single %.6f %.6f %.6f", 1 + (i + j + k) % 2,
                      -0.0095 + 0.0025 * i + 0.0001 * ((j * 7 + k) % 3),
                      -0.008 + 0.0025 * j + 0.00007 * (i % 4), -0.008 + 0.0025 * k);
        s.push_back(line);
      }
  s.push_back("set type 1 diameter 0.0012 density 2500");
  s.push_back("set type 2 diameter 0.0018 density 2500");
  s.push_back(
      std::string("fix cyl all particletemplate/multisphere 15485863 atom_type 2 density constant 1190 "
                  "nspheres 50 ntry 1000000 spheres file ") +
      GRANARY_SOURCE_DIR + "/potentials/cylinder_ellipse_50.clump scale 1.0 type 1");
  s.push_back("fix integr all multisphere");
  s.push_back("create_clump cyl 0.0005 0.0003 0.0061 quat 0.9238795 0 0.3826834 0");
  s.push_back("create_clump cyl 0.0091 -0.004 0.0062");  // across the periodic x boundary
  s.push_back("region cut block -0.0073 0.0061 -0.0052 0.0067 -0.0031 0.0064");
  s.push_back("compute phi all region-phi cut");
  s.push_back("compute phis all region-phi cut type 2 1 clump scale");
  s.push_back("region slab block EDGE EDGE -0.0052 0.0067 0.0052 0.0088");
  s.push_back("compute phip all region-phi slab");
  return s;
}

}  // namespace

TEST_CASE("region-phi: the same value on any number of ranks", "[region_phi][mpi]") {
  granary::test::ScriptEngine world(MPI_COMM_WORLD);
  world.cmds(scene());
  granary::test::ScriptEngine self(MPI_COMM_SELF);
  self.cmds(scene());
  for (const char* id : {"phi", "phis", "phip"}) {
    for (int i = 0; i <= 2; ++i) {
      const double a = world.e.compute_value(id, i), b = self.e.compute_value(id, i);
      INFO("c_" << id << "[" << i << "] on all ranks " << a << ", on one " << b);
      CHECK(a >= 0.0);
      if (i == 0) CHECK(a > 0.0);
      CHECK(a == Approx(b).epsilon(1e-12));
    }
  }
}
