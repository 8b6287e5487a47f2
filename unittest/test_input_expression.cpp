// Formula evaluation (equal- and atom-style), the if-command Boolean and
// number formats, with a stand-in Resolver instead of an Engine.
#include <catch2/catch.hpp>
#include <cmath>
#include <map>
#include <set>
#include <string>
#include <vector>

#include "core/error.h"
#include "core/expression.h"
#include "core/input.h"
#include "core/variable.h"

using granary::Args;
using granary::Expression;
using granary::InputError;
using granary::RunError;

namespace {

const double kPi = 3.14159265358979323846;

/// Four local atoms; step 50 of a run from 0 to 100 with dt 0.1.
struct TestResolver : granary::Resolver {
  std::map<std::string, double> keys{
      {"step", 50}, {"__beginstep", 0}, {"__endstep", 100}, {"dt", 0.1}, {"vol", 8}};
  std::map<std::string, std::vector<double>> atoms{
      {"id", {10, 11, 12, 13}}, {"x", {1, 2, 3, 4}}, {"mass", {1, 1, 2, 2}}, {"type", {1, 2, 1, 2}}};
  Args last_group_args;
  std::string last_group;

  bool keyword(const std::string& name, double& value) override {
    auto it = keys.find(name);
    if (it == keys.end()) return false;
    value = it->second;
    return true;
  }
  std::vector<std::string> keyword_names() override {
    std::vector<std::string> out;
    for (const auto& kv : keys)
      out.push_back(kv.first);
    return out;
  }
  double compute_value(const std::string& id, int index) override {
    if (id == "ke") return index == 0 ? 5.0 : 1.5 * index;
    throw InputError("unknown compute ID '" + id + "'");
  }
  double fix_value(const std::string& id, int index) override {
    if (id == "wall") return 100.0 + index;
    throw InputError("unknown fix ID '" + id + "'");
  }
  double group_function(const std::string& name, const Args& args) override {
    last_group = name;
    last_group_args = args;
    return name == "count" ? 4.0 : 2.5;
  }
  bool atom_vector(const std::string& name, std::vector<double>& out) override {
    auto it = atoms.find(name);
    if (it == atoms.end()) return false;
    out = it->second;
    return true;
  }
  void compute_peratom(const std::string& id, int col, std::vector<double>& out) override {
    if (id != "pa") throw InputError("compute " + id + " does not give per-atom values");
    out = {10.0 * col + 1, 10.0 * col + 2, 10.0 * col + 3, 10.0 * col + 4};
  }
  void fix_peratom(const std::string& id, int col, std::vector<double>& out) override {
    compute_peratom(id, col, out);
  }
  std::size_t nlocal() override { return 4; }
  double atom_element(const std::vector<double>& values, long long id) override {
    const auto& ids = atoms["id"];
    for (std::size_t i = 0; i < ids.size(); ++i) {
      if (static_cast<long long>(ids[i]) == id) return values.at(i);
    }
    throw InputError("there is no atom with ID " + std::to_string(id));
  }
};

double eval(const std::string& text) {
  TestResolver r;
  return Expression(text).evaluate(r);
}

std::vector<double> eval_atom(const std::string& text) {
  TestResolver r;
  std::vector<double> out;
  Expression(text).evaluate_atom(r, out);
  return out;
}

}  // namespace

TEST_CASE("operators and precedence", "[input][expression]") {
  CHECK(eval("1+2*3") == 7);
  CHECK(eval("(1+2)*3") == 9);
  CHECK(eval("10-4-3") == 3);
  CHECK(eval("10/4") == 2.5);
  CHECK(eval("2*3/4") == 1.5);
  CHECK(eval("7%3") == 1);
  CHECK(eval("-7%3") == -1);
  CHECK(eval("2^10") == 1024);
  CHECK(eval("2^3^2") == 512);  // right-associative
  CHECK(eval("-2^2") == -4);    // ^ binds tighter than unary minus
  CHECK(eval("2^-1") == 0.5);
  CHECK(eval("2*3^2") == 18);
  CHECK(eval("-3*-2") == 6);
  CHECK(eval("+5") == 5);
  CHECK(eval("--5") == 5);
  CHECK(eval("1<2") == 1);
  CHECK(eval("2<1") == 0);
  CHECK(eval("2<=2") == 1);
  CHECK(eval("3>2") == 1);
  CHECK(eval("2>=3") == 0);
  CHECK(eval("1==1") == 1);
  CHECK(eval("1!=1") == 0);
  CHECK(eval("1&&0") == 0);
  CHECK(eval("2&&3") == 1);
  CHECK(eval("1||0") == 1);
  CHECK(eval("0||0") == 0);
  CHECK(eval("1|^1") == 0);
  CHECK(eval("1|^0") == 1);
  CHECK(eval("!0") == 1);
  CHECK(eval("!3") == 0);
  CHECK(eval("!0+1") == 2);
  CHECK(eval("1+2<4") == 1);    // + before <
  CHECK(eval("1<2==1") == 1);   // < before ==
  CHECK(eval("0||1&&0") == 0);  // && before ||
  CHECK(eval("1||0&&0") == 1);
  CHECK(eval("1==1&&2==2") == 1);
  CHECK(eval("1.5e2 + .5 + 2.") == 152.5);
  CHECK(eval("3E-1*10") == Approx(3.0));
  CHECK(eval(" ( 1 +\t2 ) ") == 3);
}

TEST_CASE("constants, thermo keywords and references", "[input][expression]") {
  CHECK(eval("PI") == Approx(kPi));
  CHECK(eval("yes+on+true+no+off+false") == 3);
  CHECK(eval("vol/2") == 4);
  CHECK(eval("step") == 50);
  CHECK(eval("c_ke") == 5);
  CHECK(eval("c_ke[2]") == 3);
  CHECK(eval("f_wall[3]") == 103);
  CHECK(eval("x[12]") == 3);  // value of the atom with ID 12
  CHECK(eval("mass[13]*2") == 4);
  CHECK(eval("C_pa[11]") == 2);      // per-atom compute, atom ID 11
  CHECK(eval("C_pa[11][2]") == 22);  // column 2
  CHECK(eval("c_ke[1+1]") == 3);     // index from a formula
}

TEST_CASE("math functions", "[input][expression]") {
  CHECK(eval("sqrt(16)") == 4);
  CHECK(eval("exp(0)") == 1);
  CHECK(eval("ln(exp(2))") == Approx(2));
  CHECK(eval("log(1000)") == Approx(3));
  CHECK(eval("abs(-3)") == 3);
  CHECK(eval("sin(PI/2)") == Approx(1));
  CHECK(eval("cos(0)") == 1);
  CHECK(eval("tan(PI/4)") == Approx(1));
  CHECK(eval("asin(1)") == Approx(kPi / 2));
  CHECK(eval("acos(1)") == 0);
  CHECK(eval("atan(1)") == Approx(kPi / 4));
  CHECK(eval("atan2(1,-1)") == Approx(3 * kPi / 4));
  CHECK(eval("floor(-1.5)") == -2);
  CHECK(eval("ceil(-1.5)") == -1);
  CHECK(eval("round(2.5)") == 3);
  CHECK(eval("round(-2.4)") == -2);
  CHECK(eval("min(3,1,2)") == 1);
  CHECK(eval("max(3,1,2)") == 3);
  CHECK(eval("max(-1, min(5, 4))") == 4);
  CHECK(eval("ternary(1,5,6)") == 5);
  CHECK(eval("ternary(0,5,6)") == 6);
  CHECK(eval("is_file(no_such_file_here.txt)") == 0);
}

TEST_CASE("functions of the current step", "[input][expression]") {
  // step 50 of a run 0..100, dt 0.1
  CHECK(eval("ramp(0,10)") == Approx(5));
  CHECK(eval("ramp(10,0)") == Approx(5));
  CHECK(eval("vdisplace(1,2)") == Approx(1 + 2 * 50 * 0.1));
  CHECK(eval("swiggle(0,1,20)") == Approx(1));  // sin(2 pi / 20 * 5)
  CHECK(eval("cwiggle(0,1,20)") == Approx(1));  // 1 - cos(pi/2)
  CHECK(eval("stagger(30,10)") == 60);
  CHECK(eval("logfreq(10,2,10)") == 100);
  CHECK(eval("logfreq2(10,18,10)") == 55);
  CHECK(eval("stride(0,100,15)") == 60);
  CHECK(eval("stride(0,50,25)") == 1e20);  // past the end
  TestResolver r;
  r.keys["__endstep"] = 0;  // between runs: ramp gives its first value
  CHECK(Expression("ramp(3,7)").evaluate(r) == 3);
}

TEST_CASE("random and normal are seeded and repeatable", "[input][expression]") {
  TestResolver r;
  Expression a("random(2,3,12345)"), b("random(2,3,12345)");
  const double a1 = a.evaluate(r), a2 = a.evaluate(r);
  CHECK(a1 >= 2);
  CHECK(a1 < 3);
  CHECK(a1 != a2);             // a sequence
  CHECK(b.evaluate(r) == a1);  // same seed, same sequence
  Expression n("normal(1,0.5,777)");
  double sum = 0, sum2 = 0;
  const int m = 4000;
  for (int i = 0; i < m; ++i) {
    const double x = n.evaluate(r);
    sum += x;
    sum2 += x * x;
  }
  const double mean = sum / m, var = sum2 / m - mean * mean;
  CHECK(mean == Approx(1).margin(0.05));
  CHECK(std::sqrt(var) == Approx(0.5).margin(0.05));
  CHECK_THROWS_WITH(eval("random(0,1,0)"), Catch::Contains("positive integer"));
}

TEST_CASE("group functions pass their raw arguments", "[input][expression]") {
  TestResolver r;
  CHECK(Expression("count(all)+1").evaluate(r) == 5);
  CHECK(r.last_group_args == Args{"all"});
  CHECK(Expression("xcm( grains , x )").evaluate(r) == 2.5);
  CHECK(r.last_group == "xcm");
  CHECK(r.last_group_args == Args{"grains", "x"});
  CHECK(Expression("bound(all,zmax,box)").evaluate(r) == 2.5);
  CHECK(r.last_group_args == Args{"all", "zmax", "box"});
}

TEST_CASE("atom-style formulas evaluate whole per-atom vectors", "[input][expression]") {
  CHECK(eval_atom("x*2") == std::vector<double>{2, 4, 6, 8});
  CHECK(eval_atom("x+mass") == std::vector<double>{2, 3, 5, 6});
  CHECK(eval_atom("x>2") == std::vector<double>{0, 0, 1, 1});
  CHECK(eval_atom("(type==2)*mass") == std::vector<double>{0, 1, 0, 2});
  CHECK(eval_atom("vol/x") == std::vector<double>{8, 4, 8.0 / 3, 2});
  CHECK(eval_atom("sqrt(x*x)+step") == std::vector<double>{51, 52, 53, 54});
  CHECK(eval_atom("max(x,2.5)") == std::vector<double>{2.5, 2.5, 3, 4});
  CHECK(eval_atom("ternary(x>2,x,-x)") == std::vector<double>{-1, -2, 3, 4});
  CHECK(eval_atom("2") == std::vector<double>{2, 2, 2, 2});
  CHECK(eval_atom("c_pa") == std::vector<double>{1, 2, 3, 4});
  CHECK(eval_atom("f_pa[1]") == std::vector<double>{11, 12, 13, 14});
  CHECK(eval_atom("c_ke") == std::vector<double>{5, 5, 5, 5});  // global scalar in an atom formula
  CHECK(eval_atom("x[13]+x") == std::vector<double>{5, 6, 7, 8});
  const auto rnd = eval_atom("random(0,1,99)");
  REQUIRE(rnd.size() == 4);
  CHECK(std::set<double>(rnd.begin(), rnd.end()).size() == 4);
  for (double x : rnd)
    CHECK((x >= 0 && x < 1));
  // per-atom faults may happen on one rank only: RunError
  CHECK_THROWS_AS(eval_atom("1/(x-2)"), RunError);
  CHECK_THROWS_WITH(eval_atom("sqrt(x-3)"), Catch::Contains("sqrt()") && Catch::Contains("sqrt(x-3)"));
}

TEST_CASE("formula errors name the formula and suggest fixes", "[input][expression]") {
  CHECK_THROWS_WITH(eval("1/0"), Catch::Contains("division by zero") && Catch::Contains("'1/0'"));
  CHECK_THROWS_WITH(eval("5%0"), Catch::Contains("modulo by zero"));
  CHECK_THROWS_WITH(eval("sqrt(-1)"), Catch::Contains("sqrt() of a negative value"));
  CHECK_THROWS_WITH(eval("ln(0)"), Catch::Contains("not positive"));
  CHECK_THROWS_WITH(eval("asin(2)"), Catch::Contains("outside [-1,1]"));
  CHECK_THROWS_WITH(eval("(-8)^(1/3)"), Catch::Contains("non-integer power"));
  CHECK_THROWS_WITH(eval("0^-1"), Catch::Contains("negative power"));
  CHECK_THROWS_WITH(eval("foo(1)"), Catch::Contains("unknown function 'foo()'"));
  CHECK_THROWS_WITH(eval("sqr(4)"), Catch::Contains("did you mean 'sqrt'"));
  CHECK_THROWS_WITH(eval("atan2(1)"), Catch::Contains("atan2() takes 2 argument(s), got 1"));
  CHECK_THROWS_WITH(eval("stepp+1"),
                    Catch::Contains("unknown name 'stepp'") && Catch::Contains("did you mean 'step'"));
  CHECK_THROWS_WITH(eval("x+1"), Catch::Contains("per-atom property"));
  CHECK_THROWS_WITH(eval("c_nope"),
                    Catch::Contains("unknown compute ID 'nope'") && Catch::Contains("c_nope"));
  CHECK_THROWS_WITH(eval("x[99]"), Catch::Contains("no atom with ID 99"));
  CHECK_THROWS_WITH(eval("c_ke[0]"), Catch::Contains("must be 1 or larger"));
  CHECK_THROWS_WITH(eval("v_a"), Catch::Contains("unknown variable 'a'"));
  CHECK_THROWS_WITH(Expression("1+"), Catch::Contains("syntax error") && Catch::Contains("'1+'"));
  CHECK_THROWS_WITH(Expression("(1+2"), Catch::Contains("expected ')'"));
  CHECK_THROWS_WITH(Expression("1+2)"), Catch::Contains("unbalanced ')'"));
  CHECK_THROWS_WITH(Expression("2 3"), Catch::Contains("unexpected '3'"));
  CHECK_THROWS_WITH(Expression("1e"), Catch::Contains("malformed number"));
  CHECK_THROWS_WITH(Expression("${a}*2"), Catch::Contains("v_name"));
  CHECK_THROWS_WITH(Expression(""), Catch::Contains("empty"));
  CHECK_THROWS_AS(Expression("1 + * 2"), InputError);
  CHECK_THROWS_AS(Expression("()"), InputError);
}

TEST_CASE("deep or long formulas are refused, not crashed on", "[input][expression]") {
  std::string deep = std::string(5000, '(') + "1" + std::string(5000, ')');
  CHECK_THROWS_WITH(Expression(deep), Catch::Contains("nested too deeply"));
  CHECK_THROWS_AS(Expression(std::string(5000, '-') + "1"), InputError);
  std::string sum = "1";
  for (int i = 0; i < 5000; ++i)
    sum += "+1";
  CHECK_THROWS_AS(Expression(sum), InputError);
  std::string ok = "1";
  for (int i = 0; i < 99; ++i)
    ok += "+1";
  CHECK(eval(ok) == 100);
}

TEST_CASE("if-command Booleans compare numbers or strings", "[input][expression]") {
  using granary::script::evaluate_boolean;
  CHECK(evaluate_boolean("1 < 2"));
  CHECK_FALSE(evaluate_boolean("2 > 10"));  // numeric, not alphabetical
  CHECK(evaluate_boolean("-1 < 0"));
  CHECK(evaluate_boolean("1.5e3 == 1500"));
  CHECK(evaluate_boolean("abc == abc"));
  CHECK(evaluate_boolean("abc != abd"));
  CHECK(evaluate_boolean("abc < abd"));
  CHECK(evaluate_boolean("run_2 >= run_10"));  // strings compare alphabetically
  CHECK_FALSE(evaluate_boolean("(1 > 0) && (2 > 3)"));
  CHECK(evaluate_boolean("(1 > 0) || (2 > 3)"));
  CHECK_FALSE(evaluate_boolean("1 |^ 1"));
  CHECK(evaluate_boolean("!0"));
  CHECK(evaluate_boolean("!(1 == 2)"));
  CHECK(evaluate_boolean("1 != 2 && 3 >= 3"));
  CHECK(evaluate_boolean("yes"));
  CHECK_FALSE(evaluate_boolean("off"));
  CHECK(evaluate_boolean("5"));
  CHECK_FALSE(evaluate_boolean("0.0"));
  CHECK_THROWS_WITH(evaluate_boolean("abc == 1"), Catch::Contains("cannot compare a number"));
  CHECK_THROWS_WITH(evaluate_boolean("2*3 > 1"), Catch::Contains("$(2*3)"));
  CHECK_THROWS_WITH(evaluate_boolean("abc"), Catch::Contains("not a true/false value"));
  CHECK_THROWS_WITH(evaluate_boolean("1 <"), Catch::Contains("missing"));
  CHECK_THROWS_WITH(evaluate_boolean("(1 < 2"), Catch::Contains("missing ')'"));
  CHECK_THROWS_AS(evaluate_boolean(""), InputError);
}

TEST_CASE("number formats", "[input][expression]") {
  using granary::format_number;
  CHECK(format_number(3.14159, "%.2f") == "3.14");
  CHECK(format_number(3.14159, "%8.3f") == "   3.142");
  CHECK(format_number(1234.5, "%.3e") == "1.234e+03");
  CHECK(format_number(0.1, "%g") == "0.1");
  CHECK(format_number(2.6, "%d") == "3");
  CHECK(format_number(-7, "%05d") == "-0007");
  CHECK(format_number(2.5, "x=%g%%") == "x=2.5%");
  CHECK_THROWS_WITH(format_number(1, "%s"), Catch::Contains("not a number format"));
  CHECK_THROWS_WITH(format_number(1, "%g %g"), Catch::Contains("more than one"));
  CHECK_THROWS_WITH(format_number(1, "abc"), Catch::Contains("no '%'"));
  CHECK_THROWS_AS(format_number(1, "%99999f"), InputError);
}
