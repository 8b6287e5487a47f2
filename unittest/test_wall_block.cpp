// Wall contacts go through the pair loop's block machinery
// (contact/contact_block.h: gathered into blocks across particles, two at a
// time). Against them, contact::evaluate (the same formulas on one lane)
// contact by contact, in the order compute wall/gran/local reports them: on a
// bed of 300 beads settled in a box of plane walls or of meshed walls (fine
// triangles, so contacts cross edges and beads in corners touch several
// faces), both must give the same forces, torques and contact histories to the
// last bit, for the compiled hot kernel and for run-time slots, with the
// bed set sliding so that some contacts are at the Coulomb limit. More than one
// block of contacts, with an odd number in the last, so full blocks, the block
// boundary and the spare lane all run.
#include <catch2/catch.hpp>

#include <cmath>
#include <map>
#include <string>
#include <vector>

#include "contact/contact_model.h"
#include "core/engine.h"
#include "core/force.h"
#include "core/modify.h"
#include "core/update.h"
#include "fix/fix_wall_gran.h"
#include "mesh_files.h"
#include "pair/pair_granular.h"
#include "particles/particles.h"
#include "same_bits.h"
#include "script_engine.h"

using granary::FixWallGran;
using granary::Vec3;

namespace {

using granary::test::same_bits;

std::string rectangle_mesh(const std::string& name, const std::vector<std::array<Vec3, 3>>& rects, int nu,
                           int nv) {
  static const std::string dir = mesh_files::temp_dir();
  std::vector<mesh_files::Triangle> t;
  for (const auto& r : rects)
    mesh_files::add_rectangle(t, r[0], r[1], r[2], nu, nv);
  const std::string file = dir + "/" + name + ".stl";
  mesh_files::write_ascii(file, t);
  return file;
}

// 300 beads of two sizes poured into a 12 mm box (floor at z = 0).
void pour(granary::test::ScriptEngine& s, const std::string& model, bool mesh) {
  const double a = 0.006, h = 0.1;
  std::vector<std::string> script = {
      "units si",
      "atom_style granular",
      "boundary m m m",
      "newton off",
      "region box block -0.008 0.008 -0.008 0.008 0.0 0.1 units box",
      "create_box 2 box",
      "neighbor 0.0005 bin",
      "neigh_modify delay 0",
      granary::test::materials(2, 5.e6, 0.45, 0.7, 0.5),
      "fix m5 all property/global coefficientRollingFriction peratomtypepair 2 0.1 0.1 0.1 0.1",
      "fix m6 all property/global coefficientRollingViscousDamping peratomtypepair 2 0.2 0.2 0.2 0.2",
      "fix m7 all property/global characteristicVelocity scalar 0.5",
      "pair_style gran model " + model,
      "pair_coeff * *",
      "timestep 2e-5",
      "region fill block -0.0045 0.0045 -0.0045 0.0045 0.001 0.095 units box",
      "create_atoms 1 random 300 4711 fill overlap 0.0021 maxtry 500",
      "set type 1 diameter 0.002 density 2500",
      "set type 1 type/fraction 2 0.4 99",
      "set type 2 diameter 0.0016 density 1800",
      "velocity all set 0.3 -0.2 -0.5",
      "fix gravi all gravity 9.81 vector 0.0 0.0 -1.0",
  };
  const std::string wall = "wall/gran model " + model;
  if (mesh) {
    const std::string floor =
        rectangle_mesh("block_floor", {{Vec3(-a, -a, 0), Vec3(2 * a, 0, 0), Vec3(0, 2 * a, 0)}}, 8, 8);
    const std::string sides = rectangle_mesh("block_sides",
                                             {{Vec3(-a, -a, 0), Vec3(2 * a, 0, 0), Vec3(0, 0, h)},
                                              {Vec3(-a, a, 0), Vec3(2 * a, 0, 0), Vec3(0, 0, h)},
                                              {Vec3(-a, -a, 0), Vec3(0, 2 * a, 0), Vec3(0, 0, h)},
                                              {Vec3(a, -a, 0), Vec3(0, 2 * a, 0), Vec3(0, 0, h)}},
                                             6, 24);
    script.push_back("fix floor all mesh/surface file " + floor + " type 1");
    script.push_back("fix sides all mesh/surface file " + sides + " type 2");
    script.push_back("fix walls all " + wall + " mesh n_meshes 2 meshes floor sides");
  } else {
    script.push_back("fix zw all " + wall + " primitive type 1 zplane 0.0");
    script.push_back("fix xw1 all " + wall + " primitive type 2 xplane -0.006");
    script.push_back("fix xw2 all " + wall + " primitive type 2 xplane 0.006");
    script.push_back("fix yw1 all " + wall + " primitive type 2 yplane -0.006");
    script.push_back("fix yw2 all " + wall + " primitive type 2 yplane 0.006");
  }
  script.push_back("fix integr all nve/sphere");
  script.push_back("run 12000");
  s.cmds(script);
}

// The wall fixes' forces by post_force (the block machinery) against
// contact::evaluate contact by contact on the same stored history.
void compare(const std::string& model, bool mesh) {
  granary::test::ScriptEngine s;
  pour(s, model, mesh);
  // the bed slides sideways: some wall contacts reach the Coulomb limit
  s.cmd("set group all vx 0.01 vy -0.005");
  granary::Engine& e = s.e;
  granary::Particles& p = *e.particles;
  REQUIRE(p.nlocal == 300);
  auto* pair = dynamic_cast<granary::PairGranular*>(e.force->pair.get());
  REQUIRE(pair);
  std::size_t pos = 0;
  std::vector<std::string> words = {"model"};
  for (std::size_t a = 0, b; a < model.size(); a = b + 1) {
    b = model.find(' ', a);
    if (b == std::string::npos) b = model.size();
    words.push_back(model.substr(a, b - a));
  }
  const granary::contact::ModelSpec spec = granary::contact::parse_model_words(words, pos);
  const double dt = e.update->history_dt();
  REQUIRE(dt > 0.0);
  int contacts = 0, sliding = 0, multi = 0;
  for (const auto& fix : e.modify->fixes) {
    auto* wall = dynamic_cast<FixWallGran*>(fix.get());
    if (!wall) continue;
    // the contacts and their stored history before this step's forces
    std::vector<FixWallGran::LocalContact> before;
    wall->local_contacts(1, "the test", before);
    std::map<int, int> per_particle;
    for (const auto& lc : before)
      ++per_particle[lc.i];
    for (const auto& [i, n] : per_particle)
      multi += n > 1;
    contacts += static_cast<int>(before.size());
    // expected: contact after contact, summed per particle in that order
    std::vector<Vec3> f(p.nlocal, Vec3::Zero()), tq(p.nlocal, Vec3::Zero());
    std::vector<std::vector<double>> hist_after;
    for (const auto& lc : before) {
      const int i = lc.i;
      granary::contact::ContactState c;
      c.n = lc.n;
      c.overlap = lc.overlap;
      c.r_i = p.radius[i];
      c.r_j = 0.0;
      c.r_eff = p.radius[i];
      c.m_eff = p.rmass[i];
      c.v_rel = p.v[i] - lc.wall_v;
      c.omega_i = p.omega[i];
      c.omega_j.setZero();
      c.dt = dt;
      const int wall_type = mesh ? (lc.mesh == 0 ? 1 : 2) : (wall->id == "zw" ? 1 : 2);
      const granary::contact::PairMaterial& mat = pair->materials()(p.type[i], wall_type);
      std::vector<double> h = lc.history;
      granary::contact::ContactResult res;
      granary::contact::evaluate(spec, c, mat, h.data(), res);
      sliding += res.ft.norm() >= (1.0 - 1e-9) * mat.friction * std::abs(res.fn);
      f[i] += res.force;
      tq[i] += res.torque_i;
      hist_after.push_back(h);
    }
    // the fix's post_force alone, from zero forces
    for (int i = 0; i < p.size(); ++i) {
      p.f[i].setZero();
      p.torque[i].setZero();
    }
    wall->post_force();
    for (int i = 0; i < p.nlocal; ++i) {
      for (int d = 0; d < 3; ++d) {
        INFO("fix " << wall->id << ", particle " << i << ", component " << d << ": " << p.f[i][d] << " vs "
                    << f[i][d]);
        REQUIRE(same_bits(p.f[i][d], f[i][d]));
        REQUIRE(same_bits(p.torque[i][d], tq[i][d]));
      }
    }
    // the history the block machinery stored: the contacts are the same
    // (nothing moved), in the same order
    std::vector<FixWallGran::LocalContact> after;
    wall->local_contacts(1, "the test", after);
    REQUIRE(after.size() == before.size());
    for (std::size_t k = 0; k < after.size(); ++k) {
      REQUIRE(after[k].i == before[k].i);
      REQUIRE(after[k].history.size() == hist_after[k].size());
      for (std::size_t q = 0; q < hist_after[k].size(); ++q) {
        INFO("fix " << wall->id << ", contact " << k << ", history value " << q);
        REQUIRE(same_bits(after[k].history[q], hist_after[k][q]));
      }
    }
  }
  INFO(model << (mesh ? ", mesh walls: " : ", plane walls: ") << contacts << " wall contacts, " << sliding
             << " sliding, " << multi << " particles with more than one contact of a fix");
  // more than one block (64 contacts) with a spare lane in the last group somewhere
  REQUIRE(contacts > 130);
  REQUIRE(sliding > 0);
  REQUIRE(sliding < contacts);  // both branches of the tangential model ran
  if (mesh) REQUIRE(multi > 0);
}

}  // namespace

TEST_CASE("Plane walls through the block machinery equal contact::evaluate (hot kernel)", "[wall][lanes]") {
  compare("hertz tangential history rolling_friction cdt", false);
}

TEST_CASE("Plane walls through the block machinery equal contact::evaluate (run-time slots)",
          "[wall][lanes]") {
  compare("hertz tangential mindlin_deresiewicz rolling_friction epsd2", false);
}

TEST_CASE("Mesh walls through the block machinery equal contact::evaluate (hot kernel)",
          "[wall][mesh][lanes]") {
  compare("hertz tangential history rolling_friction cdt", true);
}

TEST_CASE("Mesh walls through the block machinery equal contact::evaluate (run-time slots)",
          "[wall][mesh][lanes]") {
  compare("hooke tangential history rolling_friction epsd2", true);
}
