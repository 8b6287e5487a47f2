// Scripts run through Input with an Engine: control flow (label/jump/next,
// if/elif/else, include, quit), print/log/echo and error locations. Also
// valid when run on several MPI ranks (rank 0 reads the scripts).
#include <mpi.h>

#include <catch2/catch.hpp>

#include "script_engine.h"
#include <cstdio>
#include <cstdlib>
#include <fstream>
#include <sstream>
#include <string>
#include <unistd.h>
#include <utility>
#include <vector>

#include "core/engine.h"
#include "core/error.h"
#include "core/input.h"
#include "core/logger.h"
#include "core/variable.h"

using granary::InputError;

namespace {

/// A scratch directory, the same on every MPI rank (rank 0 writes files).
struct Scratch {
  std::string dir;
  int rank = 0;
  Scratch() {
    MPI_Comm_rank(MPI_COMM_WORLD, &rank);
    auto tmpl = granary::test::temp_template("granary_input_");
    if (rank == 0) REQUIRE(::mkdtemp(tmpl.data()) != nullptr);
    MPI_Bcast(tmpl.data(), static_cast<int>(tmpl.size()), MPI_CHAR, 0, MPI_COMM_WORLD);
    dir = tmpl.data();
  }
  ~Scratch() {
    MPI_Barrier(MPI_COMM_WORLD);
    if (rank == 0) std::system(("rm -rf '" + dir + "'").c_str());
  }
  std::string path(const std::string& name) const { return dir + "/" + name; }
  std::string write(const std::string& name, const std::string& text) const {
    if (rank == 0) {
      std::ofstream f(path(name));
      f << text;
    }
    MPI_Barrier(MPI_COMM_WORLD);
    return path(name);
  }
  std::string read(const std::string& name) const {
    MPI_Barrier(MPI_COMM_WORLD);
    std::ifstream f(path(name));
    std::stringstream ss;
    ss << f.rdbuf();
    return ss.str();
  }
};

/// An engine that keeps the screen quiet.
struct Quiet {
  granary::Engine engine{MPI_COMM_WORLD};
  granary::Input& input = *engine.input;
  Quiet() { engine.logger->set_screen(false); }
  std::string value(const std::string& name) { return input.variables().retrieve(name); }
};

std::string error_of(Quiet& q, const std::string& path) {
  try {
    q.input.file(path);
  } catch (const InputError& e) {
    return e.what();
  }
  return "no error";
}

}  // namespace

TEST_CASE("a label/next/jump loop runs once per value", "[input][script]") {
  Scratch s;
  Quiet q;
  const std::string in = s.write("in.loop",
                                 "variable n loop 5\n"
                                 "variable seen string ''\n"
                                 "label top\n"
                                 "variable seen string ${seen}$n\n"
                                 "next n\n"
                                 "jump SELF top\n"
                                 "variable after string done\n");
  q.input.file(in);
  CHECK(q.value("seen") == "12345");
  CHECK(q.value("after") == "done");
  CHECK_FALSE(q.input.variables().find("n"));
}

TEST_CASE("nested loops with a break via if and jump", "[input][script]") {
  Scratch s;
  Quiet q;
  const std::string in = s.write("in.nested",
                                 "variable out string ''\n"
                                 "label loopa\n"
                                 "variable a loop 3\n"
                                 "  label loopb\n"
                                 "  variable b loop 4\n"
                                 "  variable out string ${out}$a$b,\n"
                                 "  if \"$b >= 2\" then \"jump SELF break\"\n"
                                 "  next b\n"
                                 "  jump SELF loopb\n"
                                 "  label break\n"
                                 "  variable b delete\n"
                                 "next a\n"
                                 "jump SELF loopa\n");
  q.input.file(in);
  CHECK(q.value("out") == "11,12,21,22,31,32,");
}

TEST_CASE("jump SELF without a label restarts the file", "[input][script]") {
  Scratch s;
  Quiet q;
  const std::string in = s.write("in.restart",
                                 "variable i loop 3\n"
                                 "variable count string x${count}\n"
                                 "next i\n"
                                 "jump SELF\n");
  q.input.variables().set({"count", "string", ""});
  q.input.file(in);
  CHECK(q.value("count") == "xxx");
}

TEST_CASE("an endless jump loop is an error, a loop that changes something is not", "[input][script]") {
  Scratch s;
  Quiet q;
  // nothing between the label and the jump can change the loop: an error at the jump's line
  const std::string endless = s.write("in.endless",
                                      "print a screen no\nlabel top\nprint b screen no\n"
                                      "jump SELF top\n");
  CHECK_THAT(error_of(q, endless), Catch::StartsWith(endless + ":4: jump: endless loop"));
  const std::string bare = s.write("in.bare", "label top\njump SELF top\n");
  CHECK_THAT(error_of(q, bare), Catch::StartsWith(bare + ":2: jump: endless loop"));
  // a loop that advances a variable runs to its end; so does one that ends with if
  const std::string counted =
      s.write("in.counted",
              "variable n loop 5\nlabel top\nprint x screen no\nnext n\njump SELF top\n"
              "variable done string yes\n");
  q.input.file(counted);
  CHECK(q.value("done") == "yes");
  const std::string with_if = s.write("in.if",
                                      "variable k equal 0\nlabel top\nvariable k equal $(v_k+1)\n"
                                      "if \"${k} >= 3\" then \"jump SELF out\"\njump SELF top\nlabel out\n");
  q.input.file(with_if);
  CHECK(q.value("k") == "3");
}

TEST_CASE("jump to a label in another file", "[input][script]") {
  Scratch s;
  Quiet q;
  s.write("in.b",
          "variable where string wrong\n"
          "label here\n"
          "variable where string b\n");
  const std::string a = s.write("in.a", "jump " + s.path("in.b") + " here\nvariable where string a\n");
  q.input.file(a);
  CHECK(q.value("where") == "b");
}

TEST_CASE("if / elif / else pick one branch", "[input][script]") {
  Quiet q;
  auto pick = [&](const std::string& x) {
    q.input.one("variable x equal " + x);
    q.input.one(
        "if \"${x} > 10\" then \"variable r string big\" &\n"
        "elif \"${x} > 3\" \"variable r string mid\" \"variable r2 string also\" &\n"
        "else \"variable r string small\"");
    return q.value("r");
  };
  // `one` takes a single line: continuation is a file feature, so build it flat
  auto pick_flat = [&](const std::string& x) {
    q.input.one("variable x equal " + x);
    q.input.one(
        "if \"${x} > 10\" then \"variable r string big\" elif \"${x} > 3\" "
        "\"variable r string mid\" \"variable r2 string also\" else \"variable r string small\"");
    return q.value("r");
  };
  (void)pick;
  CHECK(pick_flat("20") == "big");
  CHECK(pick_flat("5") == "mid");
  CHECK(q.value("r2") == "also");
  CHECK(pick_flat("1") == "small");
  q.input.one("variable name string granular");
  q.input.one("if \"${name} == granular\" then \"variable m string yes\" else \"variable m string no\"");
  CHECK(q.value("m") == "yes");
  q.input.one("if $(1+1==2) then \"variable single string ok\"");
  CHECK(q.value("single") == "ok");
  q.input.one("if \"0\" then \"variable never string set\"");
  CHECK_FALSE(q.input.variables().find("never"));
  CHECK_THROWS_WITH(q.input.one("if 1 > 0 then quit"), Catch::Contains("expected 'then'"));
  CHECK_THROWS_WITH(q.input.one("if 1 then"), Catch::Contains("no command"));
  CHECK_THROWS_WITH(q.input.one("if 1 then a else b elif 1 c"), Catch::Contains("after 'else'"));
}

TEST_CASE("include runs another file, and its variables remain", "[input][script]") {
  Scratch s;
  Quiet q;
  s.write("in.settings", "variable radius equal 0.002\nvariable name string silo\n");
  const std::string in = s.write("in.main", "include " + s.path("in.settings") +
                                                "\n"
                                                "variable d equal 2*v_radius\n");
  q.input.file(in);
  CHECK(q.input.variables().compute_equal("d") == Approx(0.004));
  CHECK(q.value("name") == "silo");
  CHECK(q.input.location().empty());
}

TEST_CASE("errors name file, line, command and the include chain", "[input][script]") {
  Scratch s;
  Quiet q;
  s.write("in.inner",
          "# comment\n"
          "variable ok equal 1\n"
          "\n"
          "primt \"hello\"\n");
  const std::string outer = s.write("in.outer",
                                    "variable a equal 1\n"
                                    "include " +
                                        s.path("in.inner") + "\n");
  const std::string msg = error_of(q, outer);
  CHECK_THAT(msg, Catch::StartsWith(s.path("in.inner") + ":4: primt: unknown command 'primt'"));
  CHECK_THAT(msg, Catch::Contains("did you mean 'print'"));
  CHECK_THAT(msg, Catch::Contains("\n  included from " + s.path("in.outer") + ":2"));

  const std::string cont = s.write("in.cont",
                                   "variable a equal &\n"
                                   "   1+\n"
                                   "variable name string x\n"
                                   "print ${nme}\n");
  const std::string m2 = error_of(q, cont);
  CHECK_THAT(m2, Catch::StartsWith(cont + ":1: variable a: syntax error"));
  const std::string bad_var = s.write("in.badvar", "variable name string x\n\nprint ${nme}\n");
  CHECK_THAT(error_of(q, bad_var), Catch::StartsWith(bad_var + ":3: print: unknown variable 'nme'") &&
                                       Catch::Contains("did you mean 'name'"));
  const std::string in_if = s.write("in.if", "if 1 then \"variable v equal 1/0\" \"print $(v_v)\"\n");
  CHECK_THAT(error_of(q, in_if), Catch::StartsWith(in_if + ":1: print: variable v: division by zero"));
  const std::string nolabel =
      s.write("in.nolabel", "print a screen no\njump SELF nowhere\nprint b screen no\n");
  CHECK_THAT(error_of(q, nolabel), Catch::StartsWith(nolabel + ":2: jump: label 'nowhere' not found"));
  CHECK_THAT(error_of(q, s.path("missing.in")), Catch::Contains("cannot open input script"));
  const std::string inc_missing = s.write("in.incmissing", "include " + s.path("nothere") + "\n");
  CHECK_THAT(error_of(q, inc_missing),
             Catch::StartsWith(inc_missing + ":1: include: cannot open input script"));
}

TEST_CASE("quit stops all files and keeps its status", "[input][script]") {
  Scratch s;
  Quiet q;
  s.write("in.inc", "variable before string yes\nquit 3\nvariable inner_after string yes\n");
  const std::string in = s.write("in.quit", "include " + s.path("in.inc") + "\nvariable after string yes\n");
  q.input.file(in);
  CHECK(q.input.quit_requested());
  CHECK(q.input.quit_status() == 3);
  CHECK(q.value("before") == "yes");
  CHECK_FALSE(q.input.variables().find("inner_after"));
  CHECK_FALSE(q.input.variables().find("after"));
}

TEST_CASE("print to files, and comments, continuation and triple quotes in files", "[input][script]") {
  Scratch s;
  Quiet q;
  const std::string out = s.path("out.txt");
  const std::string in = s.write("in.print",
                                 "variable v equal 2.5   # a comment\n"
                                 "print \"v = $v, twice $(v_v*2:%.1f) # not a comment\" file " +
                                     out +
                                     " screen no\n"
                                     "print 'second &\n"
                                     "   line' append " +
                                     out +
                                     " screen no\n"
                                     "print \"\"\"\n"
                                     "triple ${v}\n"
                                     "\"\"\" append " +
                                     out + " screen no\n");
  q.input.file(in);
  CHECK(s.read("out.txt") == "v = 2.5, twice 5.0 # not a comment\nsecond    line\n\ntriple 2.5\n\n");
  CHECK_THROWS_WITH(q.input.one("print hello world"), Catch::Contains("unknown print keyword 'world'"));
}

TEST_CASE("log and echo write commands and output to the log file", "[input][script]") {
  Scratch s;
  Quiet q;
  const std::string log = s.path("log.test");
  const std::string in = s.write("in.log", "log " + log +
                                               "\n"
                                               "echo log\n"
                                               "variable x index 4\n"
                                               "print \"x is $x\"\n"
                                               "echo none\n"
                                               "print hidden_command_shown_output\n"
                                               "log none\n"
                                               "print not_in_log\n");
  q.input.file(in);
  const std::string text = s.read("log.test");
  CHECK_THAT(text, Catch::Contains("variable x index 4\n"));
  CHECK_THAT(text, Catch::Contains("print \"x is $x\"\nx is 4\n"));
  CHECK_THAT(text, Catch::Contains("hidden_command_shown_output\n"));
  CHECK_THAT(text, !Catch::Contains("print hidden_command_shown_output"));
  CHECK_THAT(text, !Catch::Contains("not_in_log"));
  CHECK_THROWS_WITH(q.input.one("echo loud"), Catch::Contains("unknown echo style"));
}

TEST_CASE("substitution echo, one(), clear and ramp with the engine", "[input][script]") {
  Quiet q;
  q.input.one("variable z equal $(2*3)");
  CHECK(q.value("z") == "6");
  q.input.one("variable keep string here");
  q.input.one("clear");
  CHECK(q.value("keep") == "here");  // clear keeps variables
  q.input.one("variable r equal ramp(2,4)");
  CHECK(q.input.variables().compute_equal("r") == 2);  // no run yet: the first value
  q.input.one("variable s equal step");
  CHECK(q.input.variables().compute_equal("s") == 0);
  CHECK_NOTHROW(q.input.one("variable t equal stepp"));  // only parsed when defined
  CHECK_THROWS_WITH(q.input.variables().compute_equal("t"), Catch::Contains("did you mean 'step'"));
  CHECK_THROWS_WITH(q.input.one("jump SELF x"), Catch::Contains("only inside a script file"));
  std::istringstream in("variable from_stream string yes\n");
  q.input.stream(in, "test-stream");
  CHECK(q.value("from_stream") == "yes");
}

TEST_CASE("shell runs cd mkdir mv rm rmdir putenv and programs and its errors name what failed") {
  Scratch s;
  Quiet q;
  char here[4096];
  REQUIRE(::getcwd(here, sizeof here) != nullptr);
  const std::string home = here;
  const std::string script = s.write("in.shell", "shell cd " + s.dir +
                                                     "\n"
                                                     "shell mkdir a b/c\n"
                                                     "print 'hello' file a/f.txt\n"
                                                     "shell mv a/f.txt b/c\n"
                                                     "shell mv b/c/f.txt g.txt\n"
                                                     "shell putenv GRANARY_SHELL_TEST=x=1 OTHER=2\n"
                                                     "shell echo $(2*3) > h.txt\n"
                                                     "shell rm g.txt nothing.txt\n"
                                                     "shell rmdir a\n"
                                                     "shell cd b\n");
  q.input.file(script);
  char now[4096];
  REQUIRE(::getcwd(now, sizeof now) != nullptr);
  CHECK(std::string(now) == s.dir + "/b");
  REQUIRE(::chdir(home.c_str()) == 0);
  CHECK(std::string(std::getenv("GRANARY_SHELL_TEST")) == "x=1");
  CHECK(std::string(std::getenv("OTHER")) == "2");
  CHECK(s.read("h.txt") == "6\n");
  std::ifstream g(s.path("g.txt"));
  CHECK_FALSE(g.good());  // moved twice, then removed
  std::ifstream adir(s.path("a"));
  CHECK_FALSE(adir.good());
  std::ifstream cdir(s.path("b/c"));
  CHECK(cdir.good());

  const std::vector<std::pair<std::string, std::string>> bad = {
      {"shell cd " + s.dir + "/nowhere", "cannot change to directory"},
      {"shell rmdir " + s.dir + "/b", "is not empty"},
      {"shell rm " + s.dir + "/b", "is a directory"},
      {"shell mv " + s.dir + "/none.txt " + s.dir + "/x.txt", "cannot move"},
      {"shell putenv NOEQUALS", "is not VAR=VALUE"},
      {"shell", "shell needs a command"},
  };
  for (const auto& [line, expect] : bad) {
    INFO(line);
    CHECK_THROWS_WITH(q.input.one(line), Catch::Contains(expect));
  }
  CHECK(std::string(::getcwd(now, sizeof now)) == home);  // a failed cd changes nothing
}

TEST_CASE("run_style verlet is accepted and changes nothing, respa is refused", "[input]") {
  using Catch::Matchers::Contains;
  granary::test::ScriptEngine s;
  s.cmds(granary::test::free_box());
  s.cmds({"create_atoms 1 single 0 0 0 units box", "set group all diameter 0.002 density 2500",
          "velocity all set 0 0 1 units box", "fix integr all nve/sphere", "run_style verlet", "run 10"});
  CHECK(s.p().x[0].z() == Approx(10 * 1e-4 * 1.0).epsilon(1e-12));
  CHECK_THROWS_WITH(s.cmd("run_style respa 2 2"), Contains("velocity Verlet only"));
  CHECK_THROWS_WITH(s.cmd("run_style verlet inner"), Contains("takes no arguments"));
  CHECK_THROWS_WITH(s.cmd("run_style"), Contains("needs a style"));
}
