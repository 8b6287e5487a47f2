// libFuzzer target for the input language. The first byte (modulo 6, so the
// ASCII digits '0'..'5' work in seed files) picks what is fed the rest:
//   0: a whole script through Input (stand-in Engine: control flow, variables,
//      substitution, print, if, next, jump SELF, ...)
//   1: a formula, parsed and evaluated equal-style and atom-style
//   2: an if-command Boolean
//   3: line handling (comment stripping, word splitting, command reading)
//   4: a number format
//   5: $-substitution with a few variables defined
// Input errors (InputError, RunError) are expected; anything else, a crash or
// a hang is a bug.
#include <mpi.h>

#include <cstddef>
#include <cstdint>
#include <sstream>
#include <string>
#include <vector>

#include "core/engine.h"
#include "core/error.h"
#include "core/expression.h"
#include "core/input.h"
#include "core/variable.h"
#include "fuzz_engine_stub.h"

namespace {

struct Atoms : granary::Resolver {
  bool keyword(const std::string& name, double& v) override {
    if (name != "step" && name != "__beginstep" && name != "__endstep" && name != "dt") return false;
    v = name == "__endstep" ? 100 : (name == "dt" ? 0.01 : 10);
    return true;
  }
  bool atom_vector(const std::string& name, std::vector<double>& out) override {
    if (name == "id")
      out = {1, 2};
    else if (name == "x")
      out = {0.0, -2.0};
    else
      return false;
    return true;
  }
  std::size_t nlocal() override { return 2; }
  double atom_element(const std::vector<double>& values, long long id) override {
    if (id < 1 || id > 2 || values.size() < 2) throw granary::InputError("no atom");
    return values[static_cast<std::size_t>(id - 1)];
  }
  double group_function(const std::string&, const granary::Args& args) override {
    return static_cast<double>(args.size());
  }
};

template <class F>
void expect_input_errors(F f) {
  try {
    f();
  } catch (const granary::InputError&) {
  } catch (const granary::RunError&) {
  }
}

}  // namespace

// Memory that the MPI library keeps until the process ends is not ours: leaks
// are checked after each input (by libFuzzer), not at exit.
extern "C" const char* __asan_default_options() {
  return "leak_check_at_exit=0";
}

extern "C" int LLVMFuzzerInitialize(int* argc, char*** argv) {
  MPI_Init(argc, argv);
  return 0;
}

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  if (size < 1 || size > 20000) return 0;
  const int mode = data[0] % 6;
  const std::string text(reinterpret_cast<const char*>(data) + 1, size - 1);
  switch (mode) {
    case 0: {
      granary::fuzz::command_budget = 2000;
      granary::Engine engine(MPI_COMM_WORLD);
      engine.input->set_echo(false, false);
      std::istringstream in(text);
      expect_input_errors([&] { engine.input->stream(in, "fuzz"); });
      break;
    }
    case 1: {
      Atoms atoms;
      granary::Variables vars;
      vars.set_resolver(&atoms);
      vars.set({"a", "equal", "2"});
      vars.set({"p", "atom", "x*2"});
      expect_input_errors([&] {
        granary::Expression e(text);
        expect_input_errors([&] { e.evaluate(vars.resolver()); });
        std::vector<double> out;
        expect_input_errors([&] { e.evaluate_atom(vars.resolver(), out); });
      });
      break;
    }
    case 2:
      expect_input_errors([&] { granary::script::evaluate_boolean(text); });
      break;
    case 3: {
      expect_input_errors([&] { granary::script::split_words(granary::script::strip_comment(text)); });
      std::istringstream in(text);
      std::string cmd;
      int lines = 0;
      while (granary::script::read_command(in, cmd, lines)) {
        expect_input_errors([&] { granary::script::split_words(cmd); });
      }
      break;
    }
    case 4:
      expect_input_errors([&] { granary::format_number(1.25, text); });
      break;
    default: {
      granary::Variables vars;
      vars.set({"a", "index", "1", "2"});
      vars.set({"name", "string", "$(1+1)"});
      vars.set({"e", "equal", "v_a/3"});
      expect_input_errors([&] { vars.substitute(text); });
      break;
    }
  }
  return 0;
}
