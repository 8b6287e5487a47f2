// examples/silo_clogging: a shortened run of in.silo on 2 ranks (a 6 x 3 x 10 dc
// silo with a 2 dc slit, cylinders only). Checks that the avalanche CSV has
// avalanches in the agreed format, that every body is accounted for (in the
// silo, passed through the outlet, or deleted from an arch) in number and
// mass, that the CSV rows add up to what passed, and that the dumps, the
// final state (clog_*.vtp) and the box averages were written.
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

std::string read_text(const fs::path& file) {
  std::ifstream in(file);
  std::stringstream ss;
  ss << in.rdbuf();
  return ss.str();
}

std::vector<std::string> split(const std::string& s, char sep) {
  std::vector<std::string> out;
  std::stringstream ss(s);
  std::string w;
  while (std::getline(ss, w, sep))
    out.push_back(w);
  return out;
}

// "KEY value KEY value ..." after the word SILO
std::map<std::string, double> silo_line(const std::string& text) {
  std::map<std::string, double> out;
  std::istringstream in(text);
  std::string line;
  while (std::getline(in, line)) {
    if (line.rfind("SILO ", 0) != 0) continue;
    std::istringstream ws(line.substr(5));
    std::string key;
    double v;
    while (ws >> key >> v)
      out[key] = v;
  }
  return out;
}

int count_files(const fs::path& dir, const std::string& prefix, const std::string& ext) {
  int n = 0;
  for (const auto& e : fs::directory_iterator(dir)) {
    const std::string name = e.path().filename().string();
    if (name.rfind(prefix, 0) == 0 && e.path().extension() == ext && fs::file_size(e.path()) > 0) ++n;
  }
  return n;
}

}  // namespace

TEST_CASE("example silo_clogging: a short discharge with clogs, on 2 ranks", "[example][silo]") {
  const fs::path root = GRANARY_SOURCE_DIR;
  const fs::path dir = fs::temp_directory_path() / ("granary_silo_" + std::to_string(::getpid()));
  fs::remove_all(dir);
  fs::create_directories(dir);
  const std::string geom = " --W 6 --D 3 --H 10 --slit 2.0";
  const std::string mesh_cmd = "cd \"" + dir.string() + "\" && /usr/bin/python3 \"" +
                               (root / "tools" / "make_silo_stl.py").string() + "\"" + geom +
                               " --out . > mesh.out 2>&1";
  REQUIRE(std::system(mesh_cmd.c_str()) == 0);

  const std::string vars =
      " -var W 6 -var D 3 -var H 10 -var s 2.0 -var fill 7 -var stop 2 -var settle 0.08 -var timeout 0.04"
      " -var discharge_max 12000 -var dump_every 3000 -var box_w 4 -var box_h 2 -var box_z 2"
      " -var box_every 200 -var potdir \"" +
      (root / "potentials").string() + "\"";
  const std::string cmd = "cd \"" + dir.string() +
                          "\" && env -i PATH=\"$PATH\" HOME=\"$HOME\" OMPI_ALLOW_RUN_AS_ROOT=1 "
                          "OMPI_ALLOW_RUN_AS_ROOT_CONFIRM=1 OMPI_MCA_rmaps_base_oversubscribe=1 "
                          "mpirun -np 2 " GRANARY_BINARY " -in \"" +
                          (root / "examples" / "silo_clogging" / "in.silo").string() + "\"" + vars +
                          " -log none > run.out 2>&1 < /dev/null";
  const int rc = std::system(cmd.c_str());
  const std::string out = read_text(dir / "run.out");
  INFO(out);
  REQUIRE(WIFEXITED(rc));
  REQUIRE(WEXITSTATUS(rc) == 0);

  // ---- the summary line
  auto s = silo_line(out);
  REQUIRE(s.count("avalanches"));
  REQUIRE(s.count("mass_left"));
  const double avalanches = s["avalanches"];
  CHECK(avalanches >= 2);
  // every body is in the silo, passed the outlet or was deleted from an arch
  CHECK(s["initial"] == s["remaining"] + s["passed"] + s["deleted"]);
  CHECK(s["passed"] > 0);
  // mass: the same balance; cylinders only, each with the cylinder's mass rho pi a b L
  const double m_c = 1190 * M_PI * 1.6e-3 * 1.1e-3 * 3.1e-3;
  CHECK(s["mass_initial"] == Approx(s["initial"] * m_c).epsilon(1e-6));
  CHECK(s["mass_passed"] == Approx(s["passed"] * m_c).epsilon(1e-6));
  CHECK(s["mass_initial"] == Approx(s["mass_left"] + s["mass_passed"] + s["deleted"] * m_c).epsilon(1e-9));

  // ---- the avalanche CSV: comments, the agreed header, one row per avalanche
  const auto lines = split(read_text(dir / "avalanches.csv"), '\n');
  std::vector<std::vector<std::string>> rows;
  std::vector<std::string> header;
  for (const auto& l : lines) {
    if (l.empty() || l[0] == '#') continue;
    if (header.empty())
      header = split(l, ',');
    else
      rows.push_back(split(l, ','));
  }
  const std::vector<std::string> expect = {"avalanche", "t_start", "t_end",     "t_clog",      "duration",
                                           "bodies",    "mass",    "flow_rate", "fill_height", "arch_removed",
                                           "bodies_t1", "mass_t1", "bodies_t2", "mass_t2"};
  CHECK(header == expect);
  REQUIRE(static_cast<double>(rows.size()) == avalanches);
  double bodies = 0, mass = 0, t_prev = 0, arch_removed = 0;
  for (std::size_t k = 0; k < rows.size(); ++k) {
    REQUIRE(rows[k].size() == expect.size());
    CHECK(std::stoi(rows[k][0]) == static_cast<int>(k) + 1);
    const double t0 = std::stod(rows[k][1]), t1 = std::stod(rows[k][2]), tc = std::stod(rows[k][3]);
    CHECK(t0 >= t_prev);
    CHECK(t1 >= t0);
    CHECK(tc >= t1);
    t_prev = tc;
    bodies += std::stod(rows[k][5]);
    mass += std::stod(rows[k][6]);
    CHECK(std::stod(rows[k][5]) == std::stod(rows[k][10]));  // all bodies are cylinders (type 1)
    arch_removed += std::stod(rows[k][9]);
  }
  // what passed = the recorded avalanches + the one in progress; the bodies
  // deleted at the clogs, row by row, add up to the total deleted
  CHECK(bodies + s["current"] == s["passed"]);
  CHECK(arch_removed == s["deleted"]);
  CHECK(mass == Approx(bodies * m_c).epsilon(1e-6));

  // ---- dumps (particles, clumps, meshes) and the box averages
  CHECK(count_files(dir, "particles_", ".vtp") >= 3);
  CHECK(count_files(dir, "bodies_", ".vtp") >= 3);
  CHECK(count_files(dir, "mesh_", ".vtp") >= 3);
  // the final state for tools/render.py: one file each (the particles on 2 ranks as a .pvtp
  // index with its pieces), not listed in the collections
  CHECK(fs::file_size(dir / "clog_particles.pvtp") > 0);
  CHECK(fs::file_size(dir / "clog_particles_0.vtp") > 0);
  CHECK(fs::file_size(dir / "clog_bodies.vtp") > 0);
  CHECK(fs::file_size(dir / "clog_mesh.vtp") > 0);
  for (const char* pvd : {"particles_.pvd", "bodies_.pvd", "mesh_.pvd"})
    CHECK(read_text(dir / pvd).find("clog_") == std::string::npos);
  for (const char* pvd : {"clog_particles.pvd", "clog_bodies.pvd", "clog_mesh.pvd"})
    CHECK_FALSE(fs::exists(dir / pvd));
  const auto box = split(read_text(dir / "box.dat"), '\n');
  REQUIRE(box.size() >= 4);
  CHECK(box[1] == "# step time phi phi_c phi_s ke_c erot_c n_c ke_s erot_s n_s theta state");
  int data = 0;
  for (std::size_t k = 2; k < box.size(); ++k) {
    if (box[k].empty()) continue;
    std::istringstream ws(box[k]);
    std::vector<double> v;
    double x;
    while (ws >> x)
      v.push_back(x);
    REQUIRE(v.size() == 13);
    CHECK(v[2] >= 0.0);  // volume fraction of the box
    CHECK(v[2] < 0.75);
    CHECK(v[11] >= 0.0);  // mean angle to the vertical in [0, pi/2]
    CHECK(v[11] <= M_PI / 2 + 1e-12);
    ++data;
  }
  CHECK(data >= 5);
  fs::remove_all(dir);
}
