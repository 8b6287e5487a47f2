// Restart files: continuation, and bad files that must change nothing.
#include <catch2/catch.hpp>
#include <algorithm>
#include <filesystem>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstring>
#include <limits>
#include <fstream>
#include <map>
#include <string>
#include <vector>

#include "core/engine.h"
#include "core/error.h"
#include "core/input.h"
#include "core/logger.h"
#include "core/update.h"
#include "domain/domain.h"
#include "particles/particles.h"
#include "restart_scene.h"
#include "script_engine.h"

namespace {

struct State {
  std::map<long long, std::vector<double>> particles;  // id -> x v omega
  long long step = 0;
  double time = 0.0;
};

State state_of(granary::Engine& e) {
  State s;
  const auto& p = *e.particles;
  for (int i = 0; i < p.nlocal; ++i) {
    std::vector<double> v;
    for (const auto* a : {&p.x, &p.v, &p.omega})
      for (int d = 0; d < 3; ++d)
        v.push_back((*a)[i][d]);
    s.particles[p.id[i]] = v;
  }
  s.step = e.update->ntimestep;
  s.time = e.update->time();
  return s;
}

void run_lines(granary::Engine& e, const std::vector<std::string>& lines) {
  granary::test::run(e, lines);
}

std::string read_file(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  return std::string((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
}

void write_file(const std::string& path, const std::string& bytes) {
  std::ofstream(path, std::ios::binary) << bytes;
}

}  // namespace

TEST_CASE("a restarted run continues bit for bit on one rank") {
  State straight, restarted;
  {
    granary::Engine e(MPI_COMM_SELF);
    e.logger->set_screen(false);
    run_lines(e, restart_scene::fresh());
    e.input->one("run 2000");
    straight = state_of(e);
  }
  {
    granary::Engine e(MPI_COMM_SELF);
    e.logger->set_screen(false);
    run_lines(e, restart_scene::fresh());
    e.input->one("run 1000");
    e.input->one("write_restart continuation.restart");
  }
  {
    granary::Engine e(MPI_COMM_SELF);  // a new engine: nothing carried over but the file
    e.logger->set_screen(false);
    run_lines(e, restart_scene::restarted("continuation.restart"));
    e.input->one("run 1000");
    restarted = state_of(e);
  }
  REQUIRE(straight.particles.size() > 400);
  REQUIRE(restarted.particles.size() == straight.particles.size());
  CHECK(restarted.step == straight.step);
  CHECK(restarted.time == straight.time);
  int differing = 0;
  for (const auto& kv : straight.particles) {
    const auto& other = restarted.particles.at(kv.first);
    for (std::size_t k = 0; k < kv.second.size(); ++k)
      differing += kv.second[k] != other[k];
  }
  CHECK(differing == 0);  // identical to the bit
}

// A restart written in the middle of a run (restart N, or the stop of a run by
// SIGTERM) stores the forces of that step, even in the first run after the
// particles were created, so the continuation matches the run itself.
TEST_CASE("a restart written during the first run continues bit for bit on one rank") {
  State straight, restarted;
  {
    granary::Engine e(MPI_COMM_SELF);
    e.logger->set_screen(false);
    run_lines(e, restart_scene::fresh());
    e.input->one("restart 700 during.*.restart");
    e.input->one("run 2000");
    straight = state_of(e);
  }
  {
    granary::Engine e(MPI_COMM_SELF);
    e.logger->set_screen(false);
    run_lines(e, restart_scene::restarted("during.1400.restart"));
    e.input->one("run 2000 upto");
    restarted = state_of(e);
  }
  REQUIRE(straight.particles.size() > 400);
  REQUIRE(restarted.particles.size() == straight.particles.size());
  CHECK(restarted.step == straight.step);
  int differing = 0;
  for (const auto& kv : straight.particles) {
    const auto& other = restarted.particles.at(kv.first);
    for (std::size_t k = 0; k < kv.second.size(); ++k)
      differing += kv.second[k] != other[k];
  }
  CHECK(differing == 0);  // identical to the bit
}

// A script that changes particles between runs (here delete_atoms) and then
// writes a restart: the forces in memory are those of the old particle set.
// The uninterrupted script recomputes forces at the next run's setup; the
// restarted one must do the same rather than start from the stale forces.
TEST_CASE("a restart written after delete_atoms continues like the uninterrupted script") {
  const std::vector<std::string> change = {"region cut block -0.008 0.0 -0.008 0.008 0.0 0.03 units box",
                                           "delete_atoms region cut"};
  State straight, restarted;
  {
    granary::Engine e(MPI_COMM_SELF);
    e.logger->set_screen(false);
    run_lines(e, restart_scene::fresh());
    e.input->one("run 1500");
    run_lines(e, change);
    e.input->one("run 500");
    straight = state_of(e);
  }
  {
    granary::Engine e(MPI_COMM_SELF);
    e.logger->set_screen(false);
    run_lines(e, restart_scene::fresh());
    e.input->one("run 1500");
    run_lines(e, change);
    CHECK_FALSE(e.update->forces_current);
    e.input->one("write_restart changed.restart");
  }
  {
    granary::Engine e(MPI_COMM_SELF);
    e.logger->set_screen(false);
    run_lines(e, restart_scene::restarted("changed.restart"));
    e.input->one("run 500");
    restarted = state_of(e);
  }
  std::remove("changed.restart");
  REQUIRE(straight.particles.size() > 150);
  REQUIRE(restarted.particles.size() == straight.particles.size());
  int differing = 0;
  for (const auto& kv : straight.particles) {
    const auto& other = restarted.particles.at(kv.first);
    for (std::size_t k = 0; k < kv.second.size(); ++k)
      differing += kv.second[k] != other[k];
  }
  CHECK(differing == 0);  // identical to the bit
}

TEST_CASE("restart files are written to a temporary name and renamed") {
  granary::Engine e(MPI_COMM_SELF);
  e.logger->set_screen(false);
  run_lines(e, restart_scene::fresh());
  e.input->one("run 10");
  e.input->one("write_restart atomic.restart");
  CHECK(std::ifstream("atomic.restart").good());
  CHECK_FALSE(std::ifstream("atomic.restart.tmp").good());
  // periodic restarts with two alternating files and a step in the name
  e.input->one("restart 5 ping_*.restart");
  e.input->one("run 10");
  CHECK(std::ifstream("ping_15.restart").good());
  CHECK(std::ifstream("ping_20.restart").good());
  e.input->one("restart 5 a.restart b.restart");
  e.input->one("run 10");
  CHECK(std::ifstream("a.restart").good());
  CHECK(std::ifstream("b.restart").good());
}

TEST_CASE("bad restart files give a clear error and change nothing") {
  {
    granary::Engine e(MPI_COMM_SELF);
    e.logger->set_screen(false);
    run_lines(e, restart_scene::fresh());
    e.input->one("run 200");
    e.input->one("write_restart good.restart");
  }
  const std::string good = read_file("good.restart");
  REQUIRE(good.size() > 1000);

  struct Case {
    std::string name, bytes, expect;
  };
  std::string corrupted = good;
  corrupted[good.size() / 2] ^= 0x5a;  // a flipped byte in the particle data
  std::string wrong_version = good;
  wrong_version[16] = 99;
  std::string not_restart = "this is a text file, not a restart\n";
  std::string other_order = good;  // the byte-order mark as the other byte order writes it
  std::reverse(other_order.begin() + 20, other_order.begin() + 24);
  std::string flipped_mark = good;  // a damaged mark: neither order
  flipped_mark[21] ^= 0x10;
  const std::vector<Case> cases = {
      {"truncated.restart", good.substr(0, good.size() - 100), "truncated"},
      {"corrupted.restart", corrupted, "corrupted"},
      {"version.restart", wrong_version, "format version 99"},
      {"text.restart", not_restart, "not a Granary restart file"},
      {"header_only.restart", good.substr(0, 40), "truncated"},
      {"cut_in_header.restart", good.substr(0, 20), "truncated: 20 bytes, fewer than the 32 of its header"},
      {"other_order.restart", other_order, "other byte order"},
      {"flipped_mark.restart", flipped_mark, "corrupted: its byte-order mark is 0x"},
  };
  for (const auto& c : cases) {
    write_file(c.name, c.bytes);
    granary::Engine e(MPI_COMM_SELF);
    e.logger->set_screen(false);
    e.input->one("atom_style granular");
    INFO(c.name);
    CHECK_THROWS_WITH(e.input->one("read_restart " + c.name), Catch::Contains(c.expect));
    CHECK_FALSE(e.domain->box_exist);
    CHECK(e.particles->nlocal == 0);
    CHECK(e.update->ntimestep == 0);
  }
  granary::Engine e(MPI_COMM_SELF);
  e.logger->set_screen(false);
  CHECK_THROWS_WITH(e.input->one("read_restart no_such_file.restart"), Catch::Contains("cannot open"));
  std::filesystem::create_directories("dir.restart");
  CHECK_THROWS_WITH(e.input->one("read_restart dir.restart"),
                    Catch::Contains("'dir.restart' is a directory, not a restart file"));
  std::filesystem::remove("dir.restart");
  // the good file still reads after all that
  e.input->one("read_restart good.restart");
  CHECK(e.domain->box_exist);
  CHECK(e.update->ntimestep == 200);
}

namespace {
std::uint32_t crc32_of(const char* p, std::size_t n) {
  std::uint32_t c = 0xFFFFFFFFu;
  for (std::size_t i = 0; i < n; ++i) {
    c ^= static_cast<unsigned char>(p[i]);
    for (int k = 0; k < 8; ++k)
      c = (c & 1u) ? 0xEDB88320u ^ (c >> 1) : c >> 1;
  }
  return c ^ 0xFFFFFFFFu;
}

// A restart file changed inside its particles section, with every checksum
// written again (doc/restart_format.md): what a checksum cannot catch.
struct ParticleSection {
  std::string bytes;
  std::size_t offset = 0;   // of the section
  std::size_t records = 0;  // of the first particle record
  std::size_t per = 0;      // doubles per record
  explicit ParticleSection(const std::string& file) : bytes(file) {
    std::uint32_t n;
    std::memcpy(&n, bytes.data() + 24, 4);
    for (std::uint32_t k = 0; k < n; ++k) {
      const char* t = bytes.data() + 32 + k * 56;
      if (std::string(t) != "particles") continue;
      std::uint64_t off;
      std::memcpy(&off, t + 32, 8);
      offset = off;
    }
    REQUIRE(offset > 0);
    std::uint32_t nextra;
    std::memcpy(&nextra, bytes.data() + offset + 8, 4);
    std::size_t at = offset + 12;
    per = 23;
    for (std::uint32_t k = 0; k < nextra; ++k) {
      std::uint64_t len;
      std::memcpy(&len, bytes.data() + at, 8);
      std::uint32_t ncomp;
      std::memcpy(&ncomp, bytes.data() + at + 8 + len, 4);
      per += ncomp;
      at += 8 + len + 4;
    }
    records = at;
  }
  void set_value(std::size_t record, int field, double v) {
    std::memcpy(&bytes[records + (record * per + field) * 8], &v, 8);
  }
  void set_count(std::uint64_t count) { std::memcpy(&bytes[offset], &count, 8); }
  std::string sealed() const {
    std::string b = bytes;
    std::uint32_t n;
    std::memcpy(&n, b.data() + 24, 4);
    for (std::uint32_t k = 0; k < n; ++k) {
      char* t = &b[32 + k * 56];
      std::uint64_t off, size;
      std::memcpy(&off, t + 32, 8);
      std::memcpy(&size, t + 40, 8);
      const std::uint32_t c = crc32_of(b.data() + off, size);
      std::memcpy(t + 48, &c, 4);
    }
    const std::uint32_t c = crc32_of(b.data() + 32, n * 56);
    std::memcpy(&b[28], &c, 4);
    return b;
  }
};
}  // namespace

TEST_CASE("restart records with impossible values are refused before anything is read") {
  {
    granary::Engine e(MPI_COMM_SELF);
    e.logger->set_screen(false);
    run_lines(e, restart_scene::fresh());
    e.input->one("run 20");
    e.input->one("write_restart rec_good.restart");
  }
  const std::string good = read_file("rec_good.restart");
  struct Case {
    std::string name, expect;
    int record, field;
    double value;
  };
  const double inf = std::numeric_limits<double>::infinity();
  const std::vector<Case> cases = {
      {"huge_id", "particle record 2 has the id", 1, 0, -3.85e49},
      {"nan_x", "particle record 1 holds a value that is not a finite number", 0, 3, std::nan("")},
      {"inf_v", "particle record 3 holds a value that is not a finite number", 2, 7, inf},
      {"type_0", "particle record 1 has the type 0", 0, 1, 0.0},
      {"type_half", "particle record 1 has the type 1.5", 0, 1, 1.5},
      {"radius", "radius, density or mass that is not positive", 1, 18, -1e-3},
      {"body", "particle record 1 has the body", 0, 21, -7.0},
      {"image", "particle record 1 has the image flags", 0, 22, 1e12},
      {"mask", "particle record 1 has the group mask", 0, 2, -1.0},
  };
  for (const auto& c : cases) {
    ParticleSection ps(good);
    ps.set_value(c.record, c.field, c.value);
    write_file("rec_" + c.name + ".restart", ps.sealed());
    granary::Engine e(MPI_COMM_SELF);
    e.logger->set_screen(false);
    INFO(c.name);
    CHECK_THROWS_WITH(e.input->one("read_restart rec_" + c.name + ".restart"),
                      Catch::Contains(c.expect) && Catch::Contains("corrupted"));
    CHECK_FALSE(e.domain->box_exist);
    CHECK(e.particles->nlocal == 0);
  }
  {  // two records with one id
    ParticleSection ps(good);
    double first;
    std::memcpy(&first, ps.bytes.data() + ps.records, 8);
    ps.set_value(1, 0, first);
    write_file("rec_same_id.restart", ps.sealed());
    granary::Engine e(MPI_COMM_SELF);
    e.logger->set_screen(false);
    CHECK_THROWS_WITH(e.input->one("read_restart rec_same_id.restart"), Catch::Contains("the same id"));
  }
  {  // a count of particles the section cannot hold: refused before allocating for it
    ParticleSection ps(good);
    ps.set_count(std::uint64_t(1) << 60);
    write_file("rec_count.restart", ps.sealed());
    granary::Engine e(MPI_COMM_SELF);
    e.logger->set_screen(false);
    CHECK_THROWS_WITH(e.input->one("read_restart rec_count.restart"),
                      Catch::Contains("announces 1152921504606846976 particles"));
  }
  // the sealing itself changes nothing: an unchanged file sealed again reads
  write_file("rec_resealed.restart", ParticleSection(good).sealed());
  granary::Engine e(MPI_COMM_SELF);
  e.logger->set_screen(false);
  e.input->one("read_restart rec_resealed.restart");
  CHECK(e.particles->natoms > 3);
}

TEST_CASE("restart settings outside their range are refused before anything is read") {
  {
    granary::Engine e(MPI_COMM_SELF);
    e.logger->set_screen(false);
    run_lines(e, restart_scene::fresh());
    e.input->one("run 20");
    e.input->one("write_restart set_good.restart");
  }
  const std::string good = read_file("set_good.restart");
  const std::size_t at = good.find("\nneighbor ");
  REQUIRE(at != std::string::npos);
  // "neighbor SKIN EVERY DELAY CHECK SORT BINSIZE": EVERY is the third word
  const std::size_t every = good.find(' ', good.find(' ', at + 1) + 1) + 1;
  REQUIRE(good[every] == '1');
  REQUIRE(good[every + 1] == ' ');
  struct Case {
    std::string name;
    char every;
    std::string expect;
  };
  // an interval of 0 would divide by zero at the first neighbour-list decision
  for (const Case& c : {Case{"every_0", '0', "'every' is 0, not >= 1"}, Case{"every_neg", '-', "every"}}) {
    ParticleSection ps(good);
    ps.bytes[every] = c.every;
    write_file("set_" + c.name + ".restart", ps.sealed());
    granary::Engine e(MPI_COMM_SELF);
    e.logger->set_screen(false);
    INFO(c.name);
    CHECK_THROWS_WITH(e.input->one("read_restart set_" + c.name + ".restart"),
                      Catch::Contains(c.expect) && Catch::Contains("corrupted"));
    CHECK_FALSE(e.domain->box_exist);
    CHECK(e.particles->nlocal == 0);
  }
  {  // a group index that is not a number
    const std::size_t grp = good.find("\ngroup 0 all\n");
    REQUIRE(grp != std::string::npos);
    ParticleSection ps(good);
    ps.bytes[grp + 7] = 'x';
    write_file("set_group.restart", ps.sealed());
    granary::Engine e(MPI_COMM_SELF);
    e.logger->set_screen(false);
    CHECK_THROWS_WITH(e.input->one("read_restart set_group.restart"),
                      Catch::Contains("group index") && Catch::Contains("corrupted"));
    CHECK_FALSE(e.domain->box_exist);
    CHECK(e.particles->nlocal == 0);
  }
}

TEST_CASE("read_restart refuses an engine that already has a box") {
  granary::Engine e(MPI_COMM_SELF);
  e.logger->set_screen(false);
  run_lines(e, restart_scene::fresh());
  e.input->one("write_restart twice.restart");
  CHECK_THROWS_WITH(e.input->one("read_restart twice.restart"), Catch::Contains("before the box"));
}
