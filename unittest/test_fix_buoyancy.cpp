// fix buoyancy against LIGGGHTS 3.8 and Archimedes: three spheres under
// gravity with a water surface at z = 5 mm (fluid 1000 kg/m^3): one above it
// (density 500, falls in and bobs), one fully submerged and lighter than
// water (800, rises through the surface), one heavier (1500, sinks at
// g (1 - 1000/1500)). The total buoyancy force at the start is
// rho_f g (V2 + V3), as LIGGGHTS prints it; the positions of the falling and
// the sinking sphere are LIGGGHTS' (stored from its thermo output, %22.16g)
// to 12 digits, the sinking one also the closed form.
#include <catch2/catch.hpp>
#include <cmath>
#include <string>
#include <vector>

#include "core/engine.h"
#include "particles/particles.h"
#include "script_engine.h"

using Catch::Matchers::Contains;

TEST_CASE("fix buoyancy: Archimedes' force on whole and partly submerged spheres, as LIGGGHTS 3.8",
          "[fix][buoyancy][liggghts_reference]") {
  granary::test::ScriptEngine s;
  s.cmds(granary::test::liggghts_head("-0.05 0.05 -0.05 0.05 -0.05 0.05", 1));
  s.cmds({granary::test::materials(1, 5e6, 0.3, 0.5, 0.4), "pair_style gran model hertz tangential history",
          "pair_coeff * *", "create_atoms 1 single 0 0 0.02", "create_atoms 1 single 0.02 0 0.0",
          "create_atoms 1 single -0.02 0 -0.01", "set atom 1 diameter 0.01 density 500",
          "set atom 2 diameter 0.008 density 800", "set atom 3 diameter 0.006 density 1500",
          "fix grav all gravity 9.81 vector 0 0 -1", "fix bu all buoyancy level 0.005 dim z density 1000",
          "timestep 1e-5", "fix integr all nve/sphere", "run 0"});
  const double pi = 3.14159265358979323846;
  const double v2 = 4.0 / 3.0 * pi * 0.004 * 0.004 * 0.004, v3 = 4.0 / 3.0 * pi * 0.003 * 0.003 * 0.003;
  CHECK(s.e.fix_value("bu", 3) == Approx(1000 * 9.81 * (v2 + v3)).epsilon(1e-14));
  CHECK(s.e.fix_value("bu", 3) == Approx(0.003739374903714859).epsilon(1e-14));  // LIGGGHTS
  CHECK(s.e.fix_value("grav", 3) == -9.81);  // fix gravity gives its acceleration
  CHECK(s.e.fix_value("grav", 1) == 0.0);
  // LIGGGHTS 3.8 at steps 2000 and 10000: z1, z3
  struct Row {
    int step;
    double z1, z3;
  };
  const std::vector<Row> rows = {{2000, 0.018038, -0.01065399999999992},
                                 {10000, -0.009410216173480656, -0.02634999999999821}};
  int done = 0;
  for (const Row& r : rows) {
    s.cmd("run " + std::to_string(r.step - done));
    done = r.step;
    const auto& p = s.p();
    int k[4];
    for (int i = 0; i < p.nlocal; ++i)
      k[p.id[i]] = i;
    const double t = r.step * 1e-5;
    INFO("step " << r.step);
    CHECK(p.x[k[1]].z() == Approx(r.z1).epsilon(1e-12));
    CHECK(p.x[k[3]].z() == Approx(r.z3).epsilon(1e-12));
    CHECK(p.x[k[3]].z() == Approx(-0.01 - 0.5 * 9.81 * (1 - 1000.0 / 1500) * t * t).epsilon(1e-11));
  }
  CHECK_THROWS_WITH(s.cmd("fix bad all buoyancy level 0 dim w density 1"), Contains("dim must be x, y or z"));
  CHECK_THROWS_WITH(s.cmd("fix bad all buoyancy level 0 density 1"),
                    Contains("needs level, dim and density"));
  s.cmd("fix bad all buoyancy level 0 dim x density 1000");
  CHECK_THROWS_WITH(s.cmd("run 1"), Contains("must point along x"));
}
