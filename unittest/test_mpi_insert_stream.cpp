// fix insert/stream gives the same particles on 1, 2 and 4 ranks.
//
// Run by ctest at 1, 2 and 4 ranks. Every rank first runs the stream alone
// (MPI_COMM_SELF) as the reference, then all ranks run it together on
// MPI_COMM_WORLD; the particles (ids, positions, velocities) must agree. The
// face spans the subdomain boundaries, and the oblique velocity carries
// particles across them.
#include <mpi.h>

#include <catch2/catch.hpp>
#include <map>
#include <string>
#include <vector>

#include "core/engine.h"
#include "comm/collectives.h"
#include "insert_stream_scene.h"
#include "mesh_files.h"
#include "particles/particles.h"
#include "script_engine.h"

using granary::Vec3;

namespace {

std::map<long long, std::vector<double>> run_stream(MPI_Comm comm, const std::string& face) {
  granary::test::ScriptEngine s(comm);
  s.cmds(insert_stream_scene::box(face));
  s.cmds({"fix gravi all gravity 9.81 vector 0.0 0.0 -1.0",
          "fix pts1 all particletemplate/sphere 15485863 atom_type 1 density constant 2500 radius constant "
          "0.002",
          "fix pts2 all particletemplate/sphere 15485867 atom_type 1 density constant 2500 radius constant "
          "0.003",
          "fix pdd1 all particledistribution/discrete 15485867 2 pts1 0.4 pts2 0.6",
          "fix ins all insert/stream seed 32452843 distributiontemplate pdd1 nparticles 500 massrate 0.5 "
          "vel constant 0.3 0.1 -1.0 overlapcheck yes insertion_face face extrude_length 0.02",
          "fix integr all nve/sphere", "run 6002"});
  const auto& p = s.p();
  std::vector<double> mine;
  for (int i = 0; i < p.nlocal; ++i)
    mine.insert(mine.end(), {double(p.id[i]), p.x[i][0], p.x[i][1], p.x[i][2], p.v[i][0], p.v[i][1],
                             p.v[i][2], p.radius[i]});
  const std::vector<double> all = granary::allgather(comm, mine);
  std::map<long long, std::vector<double>> out;
  for (std::size_t k = 0; k + 7 < all.size(); k += 8)
    out[static_cast<long long>(all[k])] = std::vector<double>(all.begin() + k + 1, all.begin() + k + 8);
  return out;
}

}  // namespace

TEST_CASE("insert/stream inserts the same particles on every rank count", "[insert][mpi]") {
  std::vector<mesh_files::Triangle> t;
  mesh_files::add_rectangle(t, Vec3(0, 0, 0.1), Vec3(0.1, 0, 0), Vec3(0, 0.1, 0), 4, 4);
  const std::string face = mesh_files::temp_dir() + "/face.stl";
  mesh_files::write_ascii(face, t);
  const auto ref = run_stream(MPI_COMM_SELF, face);
  const auto par = run_stream(MPI_COMM_WORLD, face);
  // 4 batches of 0.5 kg/s * 0.02 s = 0.01 kg; the weights are mass fractions,
  // so the number fractions are 0.692 and 0.308 and the mean particle mass is
  // 2500 * 4/3 pi (0.692 * 8e-9 + 0.308 * 27e-9) = 1.450e-4 kg: 68.97 per batch,
  // floor(4 * 68.97) = 275
  REQUIRE(ref.size() == 275);
  REQUIRE(par.size() == ref.size());
  double worst = 0;
  for (const auto& [id, v] : ref) {
    REQUIRE(par.count(id) == 1);
    const auto& w = par.at(id);
    CHECK(w[6] == v[6]);
    for (int k = 0; k < 6; ++k)
      worst = std::max(worst, std::fabs(w[k] - v[k]));
  }
  CHECK(worst < 1e-12);
}
