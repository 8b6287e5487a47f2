// Line handling of the input language: comments, quotes, continuation, triple
// quotes and $-substitution (no Engine needed).
#include <catch2/catch.hpp>
#include <sstream>
#include <string>
#include <vector>

#include "core/error.h"
#include "core/input.h"
#include "core/variable.h"

using granary::Args;
using granary::InputError;
namespace script = granary::script;

TEST_CASE("comments are stripped outside quotes only", "[input][parse]") {
  CHECK(script::strip_comment("timestep 1.0   # a comment") == "timestep 1.0   ");
  CHECK(script::strip_comment("# whole line") == "");
  CHECK(script::strip_comment("print 'a # b' # c") == "print 'a # b' ");
  CHECK(script::strip_comment("print \"a # b\"") == "print \"a # b\"");
  CHECK(script::strip_comment("print \"\"\"x # y\"\"\" # z") == "print \"\"\"x # y\"\"\" ");
  CHECK(script::strip_comment("no comment here") == "no comment here");
}

TEST_CASE("lines split into words, quotes group words and are removed", "[input][parse]") {
  CHECK(script::split_words("  fix 1\tall   nve ") == Args{"fix", "1", "all", "nve"});
  CHECK(script::split_words("print 'a b' \"c  d\" e") == Args{"print", "a b", "c  d", "e"});
  CHECK(script::split_words("print \"\"\"line1\nline2\"\"\"") == Args{"print", "line1\nline2"});
  CHECK(script::split_words("if \"$a > 1\" then \"print 'x y'\"") ==
        Args{"if", "$a > 1", "then", "print 'x y'"});
  CHECK(script::split_words("print \"\"") == Args{"print", ""});
  CHECK(script::split_words("a'b c\"d") == Args{"a'b", "c\"d"});  // quotes inside a word are literal
  CHECK(script::split_words("   ").empty());
}

TEST_CASE("bad quoting is an error with the text", "[input][parse]") {
  CHECK_THROWS_WITH(script::split_words("print 'abc"), Catch::Contains("unclosed quote '"));
  CHECK_THROWS_WITH(script::split_words("print \"abc"), Catch::Contains("unclosed quote \""));
  CHECK_THROWS_WITH(script::split_words("print \"\"\"abc"), Catch::Contains("unclosed triple quote"));
  CHECK_THROWS_WITH(script::split_words("print \"a\"b"), Catch::Contains("followed by a blank"));
}

TEST_CASE("commands are joined across & and inside triple quotes", "[input][parse]") {
  std::istringstream in(
      "fix 1 all &\n"
      "   nve\n"
      "print \"\"\"\n"
      "one & two\n"
      "\"\"\"\n"
      "a & # comment stops the continuation\n"
      "b\r\n"
      "last &");
  std::string cmd;
  int lines = 0;
  REQUIRE(script::read_command(in, cmd, lines));
  CHECK(cmd == "fix 1 all    nve");
  CHECK(lines == 2);
  REQUIRE(script::read_command(in, cmd, lines));
  CHECK(cmd == "print \"\"\"\none & two\n\"\"\"");
  CHECK(lines == 3);
  REQUIRE(script::read_command(in, cmd, lines));
  CHECK(cmd == "a & # comment stops the continuation");
  REQUIRE(script::read_command(in, cmd, lines));
  CHECK(cmd == "b");
  REQUIRE(script::read_command(in, cmd, lines));  // ends inside a continuation
  CHECK(cmd == "last ");
  CHECK_FALSE(script::read_command(in, cmd, lines));
  CHECK(script::count_triple_quotes("a \"\"\" b \"\"\" c \"\"\"") == 3);
}

TEST_CASE("$ substitution of variables and immediate formulas", "[input][parse]") {
  granary::Variables v;
  v.set({"a", "index", "7"});
  v.set({"name", "string", "silo"});
  v.set({"e", "equal", "1/4"});
  CHECK(v.substitute("x $a y") == "x 7 y");
  CHECK(v.substitute("${name}_${a}.dump") == "silo_7.dump");
  CHECK(v.substitute("$aa") == "7a");  // single-letter name
  CHECK(v.substitute("v=${e}") == "v=0.25");
  CHECK(v.substitute("$(2*3+1)") == "7");
  CHECK(v.substitute("$(v_e*2:%.3f)") == "0.500");
  CHECK(v.substitute("$((1+2)*3)") == "9");
  CHECK(v.substitute("$(1/3)") == "0.333333333333333");
  CHECK(v.substitute("$(v_a:%d) items") == "7 items");
  // no substitution inside quotes (commands like print and if substitute later)
  CHECK(v.substitute("print '$a' \"${name}\" \"\"\"$a\"\"\" $a") ==
        "print '$a' \"${name}\" \"\"\"$a\"\"\" 7");
  // substituted text is not scanned again
  v.set({"d", "string", "'$a'"});
  CHECK(v.substitute("$d") == "'$a'");
}

TEST_CASE("$ substitution errors say what is wrong", "[input][parse]") {
  granary::Variables v;
  v.set({"name", "string", "x"});
  CHECK_THROWS_WITH(v.substitute("${nme}"),
                    Catch::Contains("unknown variable 'nme'") && Catch::Contains("did you mean 'name'"));
  CHECK_THROWS_WITH(v.substitute("${name"), Catch::Contains("missing '}'"));
  CHECK_THROWS_WITH(v.substitute("$(1+2"), Catch::Contains("missing ')'"));
  CHECK_THROWS_WITH(v.substitute("cost $ 5"), Catch::Contains("'$' must be followed"));
  CHECK_THROWS_WITH(v.substitute("$(1/0)"), Catch::Contains("division by zero"));
  CHECK_THROWS_WITH(v.substitute("$(1:%s)"), Catch::Contains("not a number format"));
  CHECK_THROWS_AS(v.substitute("$q"), InputError);
}
