// The granary program: command-line options, exit status and error reports.
#include <sys/wait.h>
#include <unistd.h>

#include <catch2/catch.hpp>

#include "script_engine.h"
#include <cstdlib>
#include <fstream>
#include <set>
#include <sstream>
#include <string>
#include <utility>
#include <vector>

#include "contact/contact_model.h"
#include "core/registry.h"
#include "core/style_list.h"

namespace {

struct Result {
  int status = -1;
  std::string out, err;
};

/// A scratch directory in which the program runs.
struct Scratch {
  std::string dir;
  Scratch() {
    auto tmpl = granary::test::temp_template("granary_cli_");
    REQUIRE(::mkdtemp(tmpl.data()) != nullptr);
    dir = tmpl.data();
  }
  ~Scratch() { std::system(("rm -rf '" + dir + "'").c_str()); }
  std::string write(const std::string& name, const std::string& text) const {
    std::ofstream f(dir + "/" + name);
    f << text;
    return name;
  }
  std::string read(const std::string& name) const {
    std::ifstream f(dir + "/" + name);
    std::stringstream ss;
    ss << f.rdbuf();
    return ss.str();
  }
  bool exists(const std::string& name) const { return std::ifstream(dir + "/" + name).good(); }

  /// Run the program in the directory with a clean environment (it must not
  /// take this MPI process's settings for its own).
  Result run(const std::string& args, const std::string& stdin_text = "") const {
    const std::string in = write(".stdin", stdin_text);
    const std::string cmd = "cd '" + dir +
                            "' && env -i PATH=\"$PATH\" HOME=\"$HOME\" timeout 120 " GRANARY_BINARY " " +
                            args + " < " + in + " > .stdout 2> .stderr";
    const int rc = std::system(cmd.c_str());
    Result r;
    r.status = WIFEXITED(rc) ? WEXITSTATUS(rc) : -1;
    r.out = read(".stdout");
    r.err = read(".stderr");
    return r;
  }
};

}  // namespace

TEST_CASE("command line: -in, -var, -log, banner and exit status", "[input][cli]") {
  Scratch s;
  s.write("in.test",
          "variable n index 1\n"  // the command line wins
          "print \"n=${n} m=${m}\"\n");
  Result r = s.run("-in in.test -var n 5 -var m a b");
  CHECK(r.status == 0);
  CHECK_THAT(r.out, Catch::StartsWith("Granary "));
  CHECK_THAT(r.out, Catch::Contains("n=5 m=a\n"));
  CHECK(r.err.empty());
  CHECK_THAT(s.read("log.granary"), Catch::Contains("n=5 m=a"));
  CHECK_THAT(s.read("log.granary"), Catch::Contains("print \"n=${n} m=${m}\""));  // echo log by default

  r = s.run("-in in.test -var n -1.5 -var m x -log other.log -echo screen");
  CHECK(r.status == 0);
  CHECK_THAT(r.out, Catch::Contains("variable n index 1\n"));  // echoed to the screen
  CHECK_THAT(r.out, Catch::Contains("n=-1.5 m=x\n"));
  CHECK(s.exists("other.log"));

  r = s.run("-in in.test -var n 1 -var m 2 -log none -screen none");
  CHECK(r.status == 0);
  CHECK(r.out.empty());
}

TEST_CASE("the script is read from standard input without -in", "[input][cli]") {
  Scratch s;
  Result r = s.run("-log none", "variable a equal 6*7\nprint \"answer $a\"\nquit 4\nprint never\n");
  CHECK(r.status == 4);
  CHECK_THAT(r.out, Catch::Contains("answer 42\n"));
  CHECK_THAT(r.out, !Catch::Contains("never"));

  // a NUL byte inside a line: refused with the place, not a line cut short
  s.write("in.nul", std::string("print first\nprint se") + '\0' + "cond\nprint never\n");
  r = s.run("-in in.nul -log none");
  CHECK(r.status == 1);
  CHECK_THAT(r.err, Catch::StartsWith("ERROR: in.nul:2: the line holds a NUL byte at column 9"));
  CHECK_THAT(r.out, Catch::Contains("first") && !Catch::Contains("never"));
}

TEST_CASE("errors: location, include chain, non-zero exit", "[input][cli]") {
  Scratch s;
  s.write("in.inner", "print ok\nfix 1 all bogus_style_name\n");
  s.write("in.main", "variable a equal 1\ninclude in.inner\nprint never\n");
  Result r = s.run("-in in.main -log none");
  CHECK(r.status == 1);
  CHECK_THAT(r.err, Catch::StartsWith("ERROR: in.inner:2: fix needs the box"));
  CHECK_THAT(r.err, Catch::Contains("\n  included from in.main:2\n"));
  CHECK_THAT(r.out, !Catch::Contains("never"));

  r = s.run("-log none", "label top\njump SELF top\n");
  CHECK(r.status == 1);
  CHECK_THAT(r.err, Catch::StartsWith("ERROR: stdin:2: jump: cannot jump back in 'stdin'"));

  r = s.run("-in no_such_file.in -log none");
  CHECK(r.status == 1);
  CHECK_THAT(r.err, Catch::Contains("ERROR: cannot open input script 'no_such_file.in'"));

  // a directory opens and reads nothing: refused, not an empty script that exits 0
  REQUIRE(std::system(("mkdir '" + s.dir + "/scripts'").c_str()) == 0);
  r = s.run("-in scripts -log none");
  CHECK(r.status == 1);
  CHECK_THAT(r.err, Catch::Contains("ERROR: 'scripts' is a directory, not an input script"));
  s.write("in.dir", "print before\ninclude scripts\nprint never\n");
  r = s.run("-in in.dir -log none");
  CHECK(r.status == 1);
  CHECK_THAT(r.err,
             Catch::StartsWith("ERROR: in.dir:2: include: 'scripts' is a directory, not an input script"));
  CHECK_THAT(r.out, !Catch::Contains("never"));
}

TEST_CASE("command line: -help and unknown options", "[input][cli]") {
  Scratch s;
  Result r = s.run("-help");
  CHECK(r.status == 0);
  CHECK_THAT(r.out, Catch::Contains("Usage: granary"));
  CHECK_THAT(r.out, Catch::Contains("-var NAME"));
  r = s.run("-inn x");
  CHECK(r.status == 1);
  CHECK_THAT(r.err,
             Catch::Contains("unknown command-line option '-inn'") && Catch::Contains("did you mean '-in'"));
  CHECK_THAT(r.err, Catch::Contains("Usage: granary"));
  r = s.run("-echo loud");
  CHECK(r.status == 1);
  CHECK_THAT(r.err, Catch::Contains("-echo needs screen, log, both or none"));
  r = s.run("-var n");
  CHECK(r.status == 1);
  CHECK_THAT(r.err, Catch::Contains("needs at least one value"));
}

TEST_CASE("command line: -list-styles prints every registered name", "[input][cli]") {
  Scratch s;
  const Result r = s.run("-list-styles");
  CHECK(r.status == 0);
  CHECK(r.err.empty());
  std::set<std::pair<std::string, std::string>> listed;
  std::istringstream lines(r.out);
  std::string line;
  while (std::getline(lines, line)) {
    std::istringstream words(line);
    std::string kind, name, extra;
    words >> kind >> name;
    INFO("line '" << line << "'");
    CHECK(!name.empty());
    CHECK(!(words >> extra));  // exactly two words
    listed.emplace(kind, name);
  }
  // No banner, no log file: only the list.
  CHECK(!s.exists("log.granary"));
  CHECK(listed.size() == granary::registered_names().size());

  auto require = [&](const std::string& kind, const std::vector<std::string>& names) {
    for (const auto& n : names) {
      INFO(kind << " " << n);
      CHECK(listed.count({kind, n}) == 1);
    }
  };
  require("command", granary::CommandRegistry::instance().names());
  require("fix", granary::FixRegistry::instance().names());
  require("compute", granary::ComputeRegistry::instance().names());
  require("pair", granary::PairRegistry::instance().names());
  require("region", granary::RegionRegistry::instance().names());
  require("dump", granary::DumpRegistry::instance().names());
  require("pair", {"none"});
  require("region", {"delete"});
  require("atom_style", {"granular", "sphere"});
  require("model", {"hertz", "hooke", "hertz/stiffness", "hooke/stiffness", "hooke/hysteresis"});
  require("tangential", {"history", "no_history"});
  require("rolling_friction", {"cdt", "epsd", "epsd2", "epsd3"});
  require("cohesion", {"sjkr", "sjkr2", "easo/capillary/viscous", "washino/capillary/viscous"});
  require("surface", {"sphere"});
  CHECK(listed.count({"tangential", "off"}) == 0);        // "off" is no sub-model
  CHECK(listed.count({"surface", "superquadric"}) == 0);  // not implemented

  // Every listed contact sub-model is accepted by the model parser, and every
  // listed atom style by atom_style.
  for (const auto& [kind, name] : listed) {
    if (kind == "model" || kind == "tangential" || kind == "rolling_friction" || kind == "cohesion" ||
        kind == "surface" || kind == "damping") {
      INFO(kind << " " << name);
      const std::vector<std::string> words = {kind, name};
      std::size_t pos = 0;
      CHECK_NOTHROW(granary::contact::parse_model_words(words, pos));
      CHECK(pos == 2);
    }
    if (kind == "atom_style") {
      INFO("atom_style " << name);
      CHECK(s.run("-log none", "atom_style " + name + "\n").status == 0);
    }
  }
  CHECK(s.run("-log none", "atom_style ellipsoid\n").status == 1);
}

TEST_CASE("the VTK module: loaded by the first VTK dump only, a missing or foreign one refused",
          "[input][cli][vtk]") {
  Scratch s;
  const std::string setup =
      "units si\n"
      "atom_style sphere\n"
      "region box block 0 10 0 10 0 10\n"
      "create_box 1 box\n"
      "create_atoms 1 single 0.5 0.5 0.5\n"
      "neighbor 0.01 bin\n"
      "info configuration\n";
  s.write("in.plain", setup + "dump d all custom 1 plain.dump id x y z\nrun 0\ninfo configuration\n");
  s.write("in.vtk", setup + "dump d all custom/vtk 1 p_*.vtp id x y z\nrun 0\ninfo configuration\n");
  // A run without VTK output never loads it (nor the VTK libraries).
  Result r = s.run("-in in.plain -log none");
  REQUIRE(r.status == 0);
  CHECK_THAT(r.out, Catch::Contains("VTK output module: not loaded"));
  CHECK_THAT(r.out, !Catch::Contains("granary_vtk.so"));
  // The first VTK dump loads it from beside the executable.
  r = s.run("-in in.vtk -log none");
  REQUIRE(r.status == 0);
  CHECK_THAT(r.out, Catch::Contains("VTK output module: not loaded"));
  CHECK_THAT(r.out, Catch::Contains("granary_vtk.so\n"));
  CHECK(s.exists("p_0.vtp"));
  CHECK(s.exists("p_.pvd"));

  const auto run_with = [&](const std::string& env, const std::string& binary) {
    const std::string cmd = "cd '" + s.dir + "' && env -i PATH=\"$PATH\" HOME=\"$HOME\" " + env +
                            " timeout 120 " + binary + " -in in.vtk -log none > .stdout 2> .stderr";
    const int rc = std::system(cmd.c_str());
    Result out;
    out.status = WIFEXITED(rc) ? WEXITSTATUS(rc) : -1;
    out.out = s.read(".stdout");
    out.err = s.read(".stderr");
    return out;
  };
  // A granary copied without its module: an error naming the script line, the
  // place it looked and the remedy.
  REQUIRE(std::system(("cp " GRANARY_BINARY " '" + s.dir + "/granary_alone'").c_str()) == 0);
  r = run_with("", "./granary_alone");
  CHECK(r.status == 1);
  CHECK_THAT(r.err, Catch::Contains("in.vtk:8"));
  CHECK_THAT(r.err, Catch::Contains(s.dir + "/granary_vtk.so"));
  CHECK_THAT(r.err, Catch::Contains("GRANARY_VTK_MODULE"));
  // GRANARY_VTK_MODULE names the module: that copy then writes its frames.
  std::system(("rm -f '" + s.dir + "'/p_*").c_str());
  r = run_with("GRANARY_VTK_MODULE=" GRANARY_VTK_MODULE_FILE, "./granary_alone");
  CHECK(r.status == 0);
  CHECK(s.exists("p_0.vtp"));
  // A module of another build, and a file that is no module, are refused.
  r = run_with("GRANARY_VTK_MODULE=" GRANARY_FOREIGN_VTK_MODULE_FILE, GRANARY_BINARY);
  CHECK(r.status == 1);
  CHECK_THAT(r.err, Catch::Contains("belongs to another build (granary 0.0.0, another build"));
  s.write("not_a_module.so", "text\n");
  r = run_with("GRANARY_VTK_MODULE=" + s.dir + "/not_a_module.so", GRANARY_BINARY);
  CHECK(r.status == 1);
  CHECK_THAT(r.err, Catch::Contains("could not be loaded from " + s.dir + "/not_a_module.so"));
}
