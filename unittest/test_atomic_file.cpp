// Files written whole (core/atomic_file.h): restart files, VTK frames, .pvd
// collections, dump frames and rewritten logs go to a temporary name that is
// renamed at the end, so no partial file ever appears under the final name,
// nothing is left behind, and a failed write names the file and keeps what was
// there.
#include <catch2/catch.hpp>
#include <unistd.h>

#include <filesystem>
#include <fstream>
#include <iterator>
#include <string>
#include <vector>

#include "core/atomic_file.h"
#include "core/engine.h"
#include "core/error.h"
#include "core/input.h"
#include "core/update.h"
#include "restart_scene.h"
#include "script_engine.h"

namespace fs = std::filesystem;
using Catch::Matchers::Contains;

namespace {

std::string fresh_dir(const std::string& name) {
  const std::string dir = "atomic_file/" + name;
  fs::remove_all(dir);
  fs::create_directories(dir);
  return dir;
}

std::string read_file(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  return std::string((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
}

/// Every entry under `dir` (recursively) whose name marks a temporary file.
std::vector<std::string> leftovers(const std::string& dir) {
  std::vector<std::string> out;
  for (const auto& f : fs::recursive_directory_iterator(dir)) {
    const std::string name = f.path().filename().string();
    if (name.find(".tmp") != std::string::npos) out.push_back(f.path().string());
  }
  return out;
}

}  // namespace

TEST_CASE("replace_file writes the whole file and leaves no temporary", "[atomic]") {
  const std::string dir = fresh_dir("basic");
  const std::string path = dir + "/a.txt";
  REQUIRE(granary::replace_file(path, std::string("first\n")) == "");
  CHECK(read_file(path) == "first\n");
  REQUIRE(granary::replace_file(path, std::string("second, longer\n")) == "");
  CHECK(read_file(path) == "second, longer\n");
  CHECK(leftovers(dir).empty());
  CHECK(granary::temp_prefix(path) == dir + "/.a.txt.tmp-");
  CHECK(granary::temp_prefix("b.vtp") == ".b.vtp.tmp-");
}

TEST_CASE("a failed write keeps the old file and removes only its own temporary", "[atomic]") {
  const std::string dir = fresh_dir("failed");
  const std::string path = dir + "/frame.vtp";
  REQUIRE(granary::replace_file(path, std::string("complete frame\n")) == "");
  // a writer (e.g. VTK) that fails after writing part of the file
  std::string seen;
  const std::string err = granary::replace_file_by_name(path, [&](const std::string& temp) -> std::string {
    seen = temp;
    std::ofstream(temp) << "half a fr";
    return "VTK could not write '" + path + "'";
  });
  CHECK(err == "VTK could not write '" + path + "'");
  CHECK(seen.rfind(granary::temp_prefix(path), 0) == 0);  // same directory, temporary name
  CHECK(read_file(path) == "complete frame\n");
  CHECK_FALSE(fs::exists(seen));
  CHECK(leftovers(dir).empty());
}

TEST_CASE("directories that look like temporaries are never used or removed", "[atomic]") {
  const std::string dir = fresh_dir("lookalikes");
  const std::string path = dir + "/state.restart";
  // the name earlier versions wrote to, and names this version might pick
  fs::create_directories(path + ".tmp");
  for (int k = 0; k < 4; ++k)
    fs::create_directories(granary::temp_prefix(path) + std::to_string(::getpid()) + "-" + std::to_string(k));
  REQUIRE(granary::replace_file(path, std::string("data")) == "");
  CHECK(read_file(path) == "data");
  CHECK(fs::is_directory(path + ".tmp"));
  for (int k = 0; k < 4; ++k)
    CHECK(
        fs::is_directory(granary::temp_prefix(path) + std::to_string(::getpid()) + "-" + std::to_string(k)));

  // the final name is a directory: the rename fails, with a message naming the
  // file; the directory and everything in it stay, the temporary is removed
  const std::string taken = dir + "/taken.vtp";
  fs::create_directories(taken + "/inside");
  const std::string err = granary::replace_file(taken, std::string("frame"));
  CHECK_THAT(err, Contains("cannot write '" + taken + "'"));
  CHECK(fs::is_directory(taken + "/inside"));
  for (const auto& f : fs::directory_iterator(dir))
    CHECK(f.path().filename().string().rfind(".taken.vtp.tmp-", 0) != 0);
}

TEST_CASE("a missing directory gives a clear error and creates nothing", "[atomic]") {
  const std::string dir = fresh_dir("missing");
  const std::string path = dir + "/nowhere/x.pvd";
  const std::string err = granary::replace_file(path, std::string("text"));
  CHECK_THAT(err, Contains("cannot write '" + path + "'"));
  CHECK_THAT(err, Contains("No such file or directory"));
  CHECK_FALSE(fs::exists(dir + "/nowhere"));
  CHECK(granary::replace_file(dir + "/", std::string("x")) != "");
}

TEST_CASE("write_restart: a directory called FILE.tmp survives, a missing directory is an error",
          "[atomic][restart]") {
  const std::string dir = fresh_dir("restart");
  granary::test::ScriptEngine s;
  s.cmds(restart_scene::fresh());
  s.cmd("run 20");
  fs::create_directories(dir + "/bed.restart.tmp");
  s.cmd("write_restart " + dir + "/bed.restart");
  CHECK(fs::is_regular_file(dir + "/bed.restart"));
  CHECK(fs::is_directory(dir + "/bed.restart.tmp"));

  const std::string missing = dir + "/no/bed.restart";
  CHECK_THROWS_WITH(s.cmd("write_restart " + missing), Contains("cannot write '" + missing + "'"));
  CHECK_FALSE(fs::exists(dir + "/no"));
  CHECK(leftovers(dir) == std::vector<std::string>{dir + "/bed.restart.tmp"});

  // the file reads back
  granary::test::ScriptEngine r;
  r.cmds(restart_scene::restarted(dir + "/bed.restart"));
  CHECK(r.e.update->count_global() == s.e.update->count_global());
}

TEST_CASE("every writer of a run leaves complete files and no temporary", "[atomic][dump]") {
  const std::string dir = fresh_dir("run");
  granary::test::ScriptEngine s;
  s.cmds(restart_scene::fresh());
  s.cmds({
      "dump v all custom/vtk 5 " + dir + "/p_*.vtp id vx",
      "dump u all custom/vtk 10 " + dir + "/g_*.vtu id",
      "dump pv all custom/vtk 10 " + dir + "/q_*.pvtp id",
      "dump leg all custom/vtk 10 " + dir + "/l_*.vtk id",
      "dump t all custom 5 " + dir + "/t_*.txt id x y z",
      "dump one all custom 5 " + dir + "/all.txt id x y z",
      "compute ke all ke",
      "fix av all ave/time 1 5 5 c_ke file " + dir + "/ke.txt",
      "restart 10 " + dir + "/r.*",
      "run 20",
  });
  CHECK(leftovers(dir).empty());
  for (const char* f : {"/p_20.vtp", "/p_.pvd", "/g_20.vtu", "/g_.pvd", "/q_20.pvtp", "/q_20_0.vtp",
                        "/l_20.vtk", "/t_20.txt", "/all.txt", "/ke.txt", "/r.10", "/r.20"})
    CHECK(fs::is_regular_file(dir + f));
  CHECK_THAT(read_file(dir + "/p_20.vtp"), Contains("</VTKFile>"));
  CHECK_THAT(read_file(dir + "/p_.pvd"), Contains("p_20.vtp"));
  const std::string ke = read_file(dir + "/ke.txt");
  CHECK(ke.rfind("# Time-averaged data for fix av\n# TimeStep c_ke\n", 0) == 0);
  CHECK_THAT(ke, Contains("\n20 "));
}

TEST_CASE("fix ave/time: a file in a missing directory is an error naming it", "[atomic][errors]") {
  const std::string dir = fresh_dir("avetime");
  granary::test::ScriptEngine s;
  s.cmds(restart_scene::fresh());
  s.cmd("compute ke all ke");
  const std::string missing = dir + "/none/ke.txt";
  CHECK_THROWS_WITH(s.cmd("fix av all ave/time 1 5 5 c_ke file " + missing),
                    Contains("cannot write '" + missing + "'"));
  CHECK_FALSE(fs::exists(dir + "/none"));
}
