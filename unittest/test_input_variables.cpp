// Variable styles, next, references between variables and their errors
// (no Engine needed).
#include <catch2/catch.hpp>
#include <cstdio>
#include <cstdlib>
#include <fstream>
#include <string>
#include <unistd.h>
#include <vector>

#include "script_engine.h"
#include "core/error.h"
#include "core/expression.h"
#include "core/variable.h"

using granary::Args;
using granary::InputError;
using granary::Variables;

namespace {

/// Two local atoms with x = 1, 3 and IDs 1, 2; thermo keyword step = 10.
struct TwoAtoms : granary::Resolver {
  bool keyword(const std::string& name, double& v) override {
    if (name != "step") return false;
    v = 10;
    return true;
  }
  bool atom_vector(const std::string& name, std::vector<double>& out) override {
    if (name == "x")
      out = {1, 3};
    else if (name == "id")
      out = {1, 2};
    else
      return false;
    return true;
  }
  std::size_t nlocal() override { return 2; }
  double atom_element(const std::vector<double>& values, long long id) override { return values.at(id - 1); }
};

}  // namespace

TEST_CASE("index variables step through their values and are then removed", "[input][variable]") {
  Variables v;
  v.set({"a", "index", "x", "y", "z"});
  CHECK(v.style("a") == "index");
  CHECK(v.retrieve("a") == "x");
  CHECK_FALSE(v.next({"a"}));
  CHECK(v.retrieve("a") == "y");
  v.set({"a", "index", "other"});  // an existing index variable is kept
  CHECK(v.retrieve("a") == "y");
  CHECK_FALSE(v.next({"a"}));
  CHECK(v.retrieve("a") == "z");
  CHECK(v.next({"a"}));  // exhausted
  CHECK_FALSE(v.find("a"));
  v.set({"a", "index", "again"});  // can be defined anew
  CHECK(v.retrieve("a") == "again");
}

TEST_CASE("loop variables, with start, end and padding", "[input][variable]") {
  Variables v;
  v.set({"i", "loop", "3"});
  std::string seen;
  do
    seen += v.retrieve("i");
  while (!v.next({"i"}));
  CHECK(seen == "123");
  v.set({"j", "loop", "8", "10", "pad"});
  CHECK(v.retrieve("j") == "08");
  v.next({"j"});
  CHECK(v.retrieve("j") == "09");
  v.next({"j"});
  CHECK(v.retrieve("j") == "10");
  CHECK(v.compute_equal("j") == 10);
  v.set({"k", "loop", "100", "pad"});
  CHECK(v.retrieve("k") == "001");
  v.set({"u", "uloop", "2"});
  CHECK(v.retrieve("u") == "1");
  CHECK_THROWS_WITH(v.set({"bad", "loop", "0"}), Catch::Contains("at least 1"));
  CHECK_THROWS_WITH(v.set({"bad", "loop", "5", "2"}), Catch::Contains("N1 <= N2"));
  CHECK_THROWS_WITH(v.set({"bad", "loop", "2.5"}), Catch::Contains("integer"));
}

TEST_CASE("next advances several variables together", "[input][variable]") {
  Variables v;
  v.set({"a", "index", "1", "2"});
  v.set({"b", "loop", "2"});
  CHECK_FALSE(v.next({"a", "b"}));
  CHECK(v.retrieve("a") == "2");
  CHECK(v.retrieve("b") == "2");
  CHECK(v.next({"a", "b"}));
  CHECK_FALSE(v.find("a"));
  CHECK_FALSE(v.find("b"));
  v.set({"e", "equal", "1"});
  CHECK_THROWS_WITH(v.next({"e"}), Catch::Contains("style equal"));
  CHECK_THROWS_WITH(v.next({"nope"}), Catch::Contains("unknown variable 'nope'"));
  CHECK_THROWS_AS(v.next({}), InputError);
}

TEST_CASE("string, equal, format, internal and getenv styles", "[input][variable]") {
  Variables v;
  v.set({"a", "index", "4"});
  v.set({"s", "string", "run_${a}"});  // string substitutes when defined
  CHECK(v.retrieve("s") == "run_4");
  v.set({"s", "string", "other"});  // string can be redefined
  CHECK(v.retrieve("s") == "other");
  v.set({"e", "equal", "v_a*2+1"});
  CHECK(v.compute_equal("e") == 9);
  CHECK(v.retrieve("e") == "9");
  v.set({"third", "equal", "1/3"});
  CHECK(v.retrieve("third") == "0.333333333333333");  // %.15g
  v.set({"spaced", "equal", "1", "+", "2"});          // unquoted words are joined
  CHECK(v.compute_equal("spaced") == 3);
  v.set({"f", "format", "third", "%.3f"});
  CHECK(v.retrieve("f") == "0.333");
  v.set({"n", "internal", "2.5"});
  CHECK(v.compute_equal("n") == 2.5);
  v.set_internal("n", 7);
  CHECK(v.retrieve("n") == "7");
  v.set({"e", "equal", "v_n*10"});  // equal can be redefined
  CHECK(v.compute_equal("e") == 70);
  ::setenv("GRANARY_TEST_ENV_VALUE", "hello", 1);
  v.set({"home", "getenv", "GRANARY_TEST_ENV_VALUE"});
  CHECK(v.retrieve("home") == "hello");
  v.set({"num", "string", "2*3"});
  CHECK(v.compute_equal("num") == 6);  // a string holding a formula
  v.set({"word", "string", "abc"});
  CHECK_THROWS_WITH(v.compute_equal("word"),
                    Catch::Contains("variable word") && Catch::Contains("not a number"));
  CHECK_THROWS_WITH(v.set({"bad", "format", "third", "%s"}), Catch::Contains("not a number format"));
  CHECK_THROWS_WITH(v.set({"bad", "string", "a", "b"}), Catch::Contains("quotes"));
  CHECK_THROWS_WITH(v.set({"bad", "internal", "x"}), Catch::Contains("needs a number"));
  CHECK_THROWS_WITH(v.set({"bad", "equal", "1+"}),
                    Catch::Contains("variable bad") && Catch::Contains("syntax error"));
}

TEST_CASE("file-style variables read one value per line", "[input][variable]") {
  auto tmpl = granary::test::temp_template("granary_varfile_");
  char* path = tmpl.data();
  const int fd = ::mkstemp(path);
  REQUIRE(fd >= 0);
  ::close(fd);
  {
    std::ofstream f(path);
    f << "# values\n  1.5 ignored\n\n2.5   # second\n";
  }
  Variables v;
  v.set({"f", "file", path});
  CHECK(v.retrieve("f") == "1.5");
  CHECK_FALSE(v.next({"f"}));
  CHECK(v.compute_equal("f") == 2.5);
  CHECK(v.next({"f"}));
  std::remove(path);
  CHECK_THROWS_WITH(v.set({"g", "file", "/nonexistent/dir/file.txt"}), Catch::Contains("cannot read file"));
}

TEST_CASE("redefinition, delete and command-line variables", "[input][variable]") {
  Variables v;
  v.set({"a", "index", "1"});
  CHECK_THROWS_WITH(v.set({"a", "equal", "2"}), Catch::Contains("already exists with style index") &&
                                                    Catch::Contains("variable a delete"));
  v.set({"a", "delete"});
  CHECK_FALSE(v.find("a"));
  v.set({"a", "delete"});  // deleting a missing variable is fine
  v.set({"a", "equal", "2"});
  CHECK(v.compute_equal("a") == 2);

  v.set_command_line("n", {"5", "6"});
  v.set({"n", "index", "1"});
  v.set({"n", "equal", "99"});  // the command line wins over any style
  CHECK(v.retrieve("n") == "5");
  CHECK_FALSE(v.next({"n"}));
  CHECK(v.retrieve("n") == "6");
  CHECK(v.next({"n"}));
  v.set({"n", "index", "1"});  // exhausted: the script may now define it
  CHECK(v.retrieve("n") == "1");

  CHECK_THROWS_WITH(v.set({"bad-name", "index", "1"}), Catch::Contains("letters, digits and underscores"));
  CHECK_THROWS_WITH(v.set({"x", "equl", "1"}), Catch::Contains("did you mean 'equal'"));
  CHECK_THROWS_WITH(v.set({"x"}), Catch::Contains("too few arguments"));
}

TEST_CASE("variables refer to each other, and cycles and unknown names are errors", "[input][variable]") {
  Variables v;
  v.set({"a", "equal", "2"});
  v.set({"b", "equal", "v_a^3"});
  CHECK(v.compute_equal("b") == 8);
  v.set({"a", "equal", "3"});  // formulas are evaluated when used
  CHECK(v.compute_equal("b") == 27);
  v.set({"p", "equal", "v_q+1"});
  v.set({"q", "equal", "v_p+1"});
  CHECK_THROWS_WITH(v.compute_equal("p"),
                    Catch::Contains("refers to itself") && Catch::Contains("p -> q -> p"));
  v.set({"c", "equal", "v_aa"});
  CHECK_THROWS_WITH(v.compute_equal("c"),
                    Catch::Contains("unknown variable 'aa'") && Catch::Contains("did you mean 'a'"));
  CHECK_THROWS_WITH(v.compute_equal("bb"),
                    Catch::Contains("unknown variable 'bb'") && Catch::Contains("did you mean 'b'"));
  v.set({"z", "equal", "1/(v_a-3)"});
  CHECK_THROWS_WITH(v.compute_equal("z"), Catch::Contains("variable z") &&
                                              Catch::Contains("division by zero") &&
                                              Catch::Contains("1/(v_a-3)"));
  CHECK(v.evaluate("v_a*v_b") == 81);
}

TEST_CASE("atom-style variables with per-atom data", "[input][variable]") {
  TwoAtoms atoms;
  Variables v;
  v.set_resolver(&atoms);
  v.set({"k", "equal", "step/10"});
  v.set({"d", "atom", "x*v_k+1"});
  v.set({"dd", "atom", "v_d*2"});
  std::vector<double> out;
  v.compute_atom("d", out);
  CHECK(out == std::vector<double>{2, 4});
  v.compute_atom("dd", out);
  CHECK(out == std::vector<double>{4, 8});
  v.compute_atom("k", out);  // an equal-style variable repeated per atom
  CHECK(out == std::vector<double>{1, 1});
  CHECK(v.is_atom("d"));
  CHECK(v.evaluate("v_d[2]") == 4);  // one atom of an atom-style variable
  CHECK_THROWS_WITH(v.compute_equal("d"), Catch::Contains("v_d[ID]"));
  CHECK_THROWS_WITH(v.retrieve("d"), Catch::Contains("cannot be substituted"));
  CHECK_THROWS_WITH(v.evaluate("v_d+1"), Catch::Contains("atom-style variable"));
  v.evaluate_atom("x+step", out);
  CHECK(out == std::vector<double>{11, 13});
}
