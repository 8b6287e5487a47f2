// Formula parser (recursive descent) and vectorised evaluator; see expression.h.
#include "core/expression.h"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <fstream>
#include <functional>
#include <limits>

#include "core/error.h"

namespace granary {

// ---------------------------------------------------------------- Resolver defaults

namespace {
[[noreturn]] void unavailable(const std::string& what) {
  throw InputError(what + " cannot be used here (no simulation is attached to this formula)");
}
}  // namespace

using Vec = std::vector<double>;
double Resolver::compute_value(const std::string& id, int) {
  unavailable("c_" + id);
}
double Resolver::fix_value(const std::string& id, int) {
  unavailable("f_" + id);
}
double Resolver::group_function(const std::string& name, const Args&) {
  unavailable(name + "()");
}
bool Resolver::atom_vector(const std::string&, Vec&) {
  return false;
}
void Resolver::compute_peratom(const std::string& id, int, Vec&) {
  unavailable("per-atom c_" + id);
}
void Resolver::fix_peratom(const std::string& id, int, Vec&) {
  unavailable("per-atom f_" + id);
}
std::size_t Resolver::nlocal() {
  return 0;
}
double Resolver::atom_element(const Vec&, long long) {
  unavailable("a value of one atom");
}
bool Resolver::variable_exists(const std::string&) {
  return false;
}
bool Resolver::variable_is_atom(const std::string&) {
  return false;
}
double Resolver::variable_value(const std::string& name) {
  unavailable("v_" + name);
}
void Resolver::variable_atom(const std::string& name, Vec&) {
  unavailable("v_" + name);
}

// ---------------------------------------------------------------- tree

namespace expr_detail {

enum class Op { Add, Sub, Mul, Div, Mod, Pow, Lt, Le, Gt, Ge, Eq, Ne, And, Or, Xor, Neg, Not, Plus };

enum class Fn {
  Sqrt,
  Exp,
  Ln,
  Log,
  Abs,
  Sin,
  Cos,
  Tan,
  Asin,
  Acos,
  Atan,
  Atan2,
  Floor,
  Ceil,
  Round,
  Min,
  Max,
  Random,
  Normal,
  Ternary,
  Ramp,
  Stagger,
  Logfreq,
  Logfreq2,
  Stride,
  Vdisplace,
  Swiggle,
  Cwiggle
};

struct FnInfo {
  const char* name;
  Fn fn;
  int min_args, max_args;  // max -1: any number
};

const FnInfo kFunctions[] = {
    {"sqrt", Fn::Sqrt, 1, 1},       {"exp", Fn::Exp, 1, 1},
    {"ln", Fn::Ln, 1, 1},           {"log", Fn::Log, 1, 1},
    {"abs", Fn::Abs, 1, 1},         {"sin", Fn::Sin, 1, 1},
    {"cos", Fn::Cos, 1, 1},         {"tan", Fn::Tan, 1, 1},
    {"asin", Fn::Asin, 1, 1},       {"acos", Fn::Acos, 1, 1},
    {"atan", Fn::Atan, 1, 1},       {"atan2", Fn::Atan2, 2, 2},
    {"floor", Fn::Floor, 1, 1},     {"ceil", Fn::Ceil, 1, 1},
    {"round", Fn::Round, 1, 1},     {"min", Fn::Min, 2, -1},
    {"max", Fn::Max, 2, -1},        {"random", Fn::Random, 3, 3},
    {"normal", Fn::Normal, 3, 3},   {"ternary", Fn::Ternary, 3, 3},
    {"ramp", Fn::Ramp, 2, 2},       {"stagger", Fn::Stagger, 2, 2},
    {"logfreq", Fn::Logfreq, 3, 3}, {"logfreq2", Fn::Logfreq2, 3, 3},
    {"stride", Fn::Stride, 3, 3},   {"vdisplace", Fn::Vdisplace, 2, 2},
    {"swiggle", Fn::Swiggle, 3, 3}, {"cwiggle", Fn::Cwiggle, 3, 3},
};

const char* const kGroupFunctions[] = {"count",    "mass", "charge", "xcm",    "vcm",     "fcm",  "bound",
                                       "gyration", "ke",   "angmom", "torque", "inertia", "omega"};

/// Park-Miller minimal standard generator (Schrage-free: 64-bit products).
struct Rng {
  explicit Rng(long long seed) {
    long long s = seed % 2147483646LL;
    if (s <= 0) s += 2147483646LL;
    state = s;
  }
  double uniform() {
    state = (16807LL * state) % 2147483647LL;
    return static_cast<double>(state) / 2147483647.0;
  }
  double gaussian() {
    if (have_spare) {
      have_spare = false;
      return spare;
    }
    double u, v, s;
    do {
      u = 2.0 * uniform() - 1.0;
      v = 2.0 * uniform() - 1.0;
      s = u * u + v * v;
    } while (s >= 1.0 || s == 0.0);
    const double f = std::sqrt(-2.0 * std::log(s) / s);
    spare = v * f;
    have_spare = true;
    return u * f;
  }
  long long state;
  bool have_spare = false;
  double spare = 0.0;
};

struct Node {
  enum Kind { Number, Unary, Binary, Func, Group, Name, AtomValue, Ref, IsFile } kind = Number;
  double value = 0.0;
  Op op = Op::Add;
  Fn fn = Fn::Sqrt;
  std::string name;                         // identifier, function name or reference ID
  char ref = 0;                             // 'c' 'f' 'v' 'C' 'F'
  std::vector<std::unique_ptr<Node>> kids;  // operands, arguments or indices
  Args raw;                                 // group-function arguments
  int height = 1;
  mutable std::unique_ptr<Rng> rng[2];  // [0] equal-style, [1] atom-style
};

}  // namespace expr_detail

using expr_detail::Fn;
using expr_detail::Node;
using expr_detail::Op;

namespace {

constexpr int kMaxHeight = 1000;  // taller trees are refused (stack safety)
constexpr int kMaxDepth = 250;    // parentheses / unary operators nested deeper are refused
constexpr std::size_t kMaxText = 100000;

/// An evaluation fault that Expression turns into an InputError naming the formula.
class EvalError : public InputError {
 public:
  using InputError::InputError;
};

std::string snippet(const std::string& s, std::size_t pos) {
  std::string rest = s.substr(std::min(pos, s.size()), 24);
  if (pos + 24 < s.size()) rest += "...";
  return rest;
}

bool is_ident_start(char c) {
  return std::isalpha(static_cast<unsigned char>(c)) || c == '_';
}
bool is_ident_char(char c) {
  return std::isalnum(static_cast<unsigned char>(c)) || c == '_';
}

std::vector<std::string> builtin_names() {
  std::vector<std::string> out;
  for (const auto& f : expr_detail::kFunctions)
    out.emplace_back(f.name);
  for (const char* g : expr_detail::kGroupFunctions)
    out.emplace_back(g);
  out.emplace_back("is_file");
  for (const char* c : {"PI", "on", "off", "true", "false", "yes", "no"})
    out.emplace_back(c);
  return out;
}

// ---------------------------------------------------------------- parser

class Parser {
 public:
  explicit Parser(const std::string& text) : s_(text) {}

  std::unique_ptr<Node> parse() {
    if (s_.size() > kMaxText) throw InputError("expression is too long (over 100000 characters)");
    skip_ws();
    if (pos_ >= s_.size()) fail("the expression is empty");
    auto n = parse_binary(0);
    skip_ws();
    if (pos_ < s_.size()) {
      if (s_[pos_] == ')') fail("unbalanced ')'");
      fail("unexpected '" + snippet(s_, pos_) + "'");
    }
    return n;
  }

 private:
  [[noreturn]] void fail(const std::string& what) const {
    std::string hint;
    if (s_.find('$') != std::string::npos) {
      hint = " ('$' is not substituted inside quotes: refer to variables as v_name)";
    }
    throw InputError("syntax error in expression '" + s_ + "' at character " + std::to_string(pos_ + 1) +
                     ": " + what + hint);
  }
  void skip_ws() {
    while (pos_ < s_.size() && std::isspace(static_cast<unsigned char>(s_[pos_])))
      ++pos_;
  }
  bool peek(const char* tok) {
    skip_ws();
    return s_.compare(pos_, std::char_traits<char>::length(tok), tok) == 0;
  }
  bool accept(const char* tok) {
    if (!peek(tok)) return false;
    pos_ += std::char_traits<char>::length(tok);
    return true;
  }
  void expect(char c, const std::string& what) {
    skip_ws();
    if (pos_ >= s_.size() || s_[pos_] != c) {
      fail(std::string("expected '") + c + "' " + what +
           (pos_ < s_.size() ? ", found '" + snippet(s_, pos_) + "'" : ", found the end"));
    }
    ++pos_;
  }
  std::unique_ptr<Node> make(Node::Kind kind) {
    auto n = std::make_unique<Node>();
    n->kind = kind;
    return n;
  }
  std::unique_ptr<Node> finish(std::unique_ptr<Node> n) {
    for (const auto& k : n->kids)
      n->height = std::max(n->height, k->height + 1);
    if (n->height > kMaxHeight) fail("the expression is nested too deeply or too long");
    return n;
  }
  std::unique_ptr<Node> binary(Op op, std::unique_ptr<Node> a, std::unique_ptr<Node> b) {
    auto n = make(Node::Binary);
    n->op = op;
    n->kids.push_back(std::move(a));
    n->kids.push_back(std::move(b));
    return finish(std::move(n));
  }

  // Binary levels, lowest precedence first.
  std::unique_ptr<Node> parse_binary(int level) {
    if (level == 6) return parse_unary();
    auto lhs = parse_binary(level + 1);
    for (;;) {
      Op op;
      if (!match_op(level, op)) return lhs;
      auto rhs = parse_binary(level + 1);
      lhs = binary(op, std::move(lhs), std::move(rhs));
    }
  }
  bool match_op(int level, Op& op) {
    switch (level) {
      case 0:
        if (accept("||")) return op = Op::Or, true;
        if (accept("|^")) return op = Op::Xor, true;
        return false;
      case 1:
        return accept("&&") ? (op = Op::And, true) : false;
      case 2:
        if (accept("==")) return op = Op::Eq, true;
        if (accept("!=")) return op = Op::Ne, true;
        return false;
      case 3:
        if (accept("<=")) return op = Op::Le, true;
        if (accept(">=")) return op = Op::Ge, true;
        if (accept("<")) return op = Op::Lt, true;
        if (accept(">")) return op = Op::Gt, true;
        return false;
      case 4:
        if (accept("+")) return op = Op::Add, true;
        if (accept("-")) return op = Op::Sub, true;
        return false;
      default:
        if (accept("*")) return op = Op::Mul, true;
        if (accept("/")) return op = Op::Div, true;
        if (accept("%")) return op = Op::Mod, true;
        return false;
    }
  }

  std::unique_ptr<Node> parse_unary() {
    if (++depth_ > kMaxDepth) fail("the expression is nested too deeply");
    Op op = Op::Plus;
    const bool unary = !peek("!=") && ((accept("-") && (op = Op::Neg, true)) ||
                                       (accept("!") && (op = Op::Not, true)) || accept("+"));
    std::unique_ptr<Node> n;
    if (unary) {
      n = make(Node::Unary);
      n->op = op;
      n->kids.push_back(parse_unary());
      n = finish(std::move(n));
    } else {
      n = parse_power();
    }
    --depth_;
    return n;
  }

  std::unique_ptr<Node> parse_power() {
    auto base = parse_primary();
    if (accept("^")) return binary(Op::Pow, std::move(base), parse_unary());
    return base;
  }

  std::unique_ptr<Node> parse_number() {
    const std::size_t start = pos_;
    while (pos_ < s_.size() && std::isdigit(static_cast<unsigned char>(s_[pos_])))
      ++pos_;
    if (pos_ < s_.size() && s_[pos_] == '.') {
      ++pos_;
      while (pos_ < s_.size() && std::isdigit(static_cast<unsigned char>(s_[pos_])))
        ++pos_;
    }
    if (pos_ < s_.size() && (s_[pos_] == 'e' || s_[pos_] == 'E')) {
      std::size_t p = pos_ + 1;
      if (p < s_.size() && (s_[p] == '+' || s_[p] == '-')) ++p;
      if (p < s_.size() && std::isdigit(static_cast<unsigned char>(s_[p]))) {
        pos_ = p;
        while (pos_ < s_.size() && std::isdigit(static_cast<unsigned char>(s_[pos_])))
          ++pos_;
      }
    }
    auto n = make(Node::Number);
    n->value = std::strtod(s_.substr(start, pos_ - start).c_str(), nullptr);
    if (pos_ < s_.size() && is_ident_char(s_[pos_])) {
      fail("malformed number '" + snippet(s_, start) + "'");
    }
    return n;
  }

  /// Raw comma-separated words up to the matching ')' (group functions, is_file).
  Args raw_args() {
    Args out;
    std::string cur;
    int depth = 0;
    while (pos_ < s_.size()) {
      const char c = s_[pos_++];
      if (c == '(') ++depth;
      if (c == ')' && depth-- == 0) {
        out.push_back(cur);
        for (auto& w : out) {
          const auto b = w.find_first_not_of(" \t\r\n");
          const auto e = w.find_last_not_of(" \t\r\n");
          w = b == std::string::npos ? "" : w.substr(b, e - b + 1);
          if (w.empty()) fail("empty argument");
        }
        return out;
      }
      if (c == ',' && depth == 0) {
        out.push_back(cur);
        cur.clear();
      } else {
        cur += c;
      }
    }
    fail("missing ')'");
  }

  std::unique_ptr<Node> parse_index() {
    ++pos_;  // '['
    auto idx = parse_binary(0);
    expect(']', "to close the index");
    return idx;
  }

  std::unique_ptr<Node> parse_primary() {
    skip_ws();
    if (pos_ >= s_.size()) fail("the expression ends where a value was expected");
    const char c = s_[pos_];
    if (std::isdigit(static_cast<unsigned char>(c)) ||
        (c == '.' && pos_ + 1 < s_.size() && std::isdigit(static_cast<unsigned char>(s_[pos_ + 1])))) {
      return parse_number();
    }
    if (c == '(') {
      ++pos_;
      skip_ws();
      if (pos_ < s_.size() && s_[pos_] == ')') fail("empty parentheses");
      auto n = parse_binary(0);
      expect(')', "to close '('");
      return n;
    }
    if (!is_ident_start(c)) {
      if (c == ')') fail("a value is missing before ')'");
      if (c == '$') fail("unexpected '$'");
      fail("expected a number, a name or '(' but found '" + snippet(s_, pos_) + "'");
    }
    const std::size_t start = pos_;
    while (pos_ < s_.size() && is_ident_char(s_[pos_]))
      ++pos_;
    const std::string name = s_.substr(start, pos_ - start);
    skip_ws();
    if (pos_ < s_.size() && s_[pos_] == '(') {
      ++pos_;
      return parse_call(name);
    }
    const bool is_ref =
        name.size() > 2 && name[1] == '_' &&
        (name[0] == 'c' || name[0] == 'f' || name[0] == 'v' || name[0] == 'C' || name[0] == 'F');
    if (is_ref) {
      auto n = make(Node::Ref);
      n->ref = name[0];
      n->name = name.substr(2);
      while (n->kids.size() < 2 && pos_ < s_.size() && s_[pos_] == '[') {
        n->kids.push_back(parse_index());
        skip_ws();
      }
      return finish(std::move(n));
    }
    if (pos_ < s_.size() && s_[pos_] == '[') {
      auto n = make(Node::AtomValue);
      n->name = name;
      n->kids.push_back(parse_index());
      return finish(std::move(n));
    }
    auto n = make(Node::Number);
    if (name == "PI") {
      n->value = 3.14159265358979323846;
    } else if (name == "on" || name == "true" || name == "yes") {
      n->value = 1.0;
    } else if (name == "off" || name == "false" || name == "no") {
      n->value = 0.0;
    } else {
      n->kind = Node::Name;
      n->name = name;
    }
    return n;
  }

  std::unique_ptr<Node> parse_call(const std::string& name) {
    for (const char* g : expr_detail::kGroupFunctions) {
      if (name == g) {
        auto n = make(Node::Group);
        n->name = name;
        n->raw = raw_args();
        return n;
      }
    }
    if (name == "is_file") {
      auto n = make(Node::IsFile);
      n->raw = raw_args();
      if (n->raw.size() != 1) fail("is_file() takes one file name");
      return n;
    }
    const expr_detail::FnInfo* info = nullptr;
    for (const auto& f : expr_detail::kFunctions) {
      if (name == f.name) info = &f;
    }
    if (!info) {
      std::string msg = "unknown function '" + name + "()'";
      const std::string hint = did_you_mean(name, builtin_names());
      fail(hint.empty() ? msg : msg + "; " + hint);
    }
    auto n = make(Node::Func);
    n->fn = info->fn;
    n->name = name;
    skip_ws();
    if (pos_ < s_.size() && s_[pos_] == ')') {
      ++pos_;
    } else {
      for (;;) {
        n->kids.push_back(parse_binary(0));
        skip_ws();
        if (pos_ < s_.size() && s_[pos_] == ',') {
          ++pos_;
          continue;
        }
        expect(')', "to close " + name + "(");
        break;
      }
    }
    const int nargs = static_cast<int>(n->kids.size());
    if (nargs < info->min_args || (info->max_args >= 0 && nargs > info->max_args)) {
      std::string want = std::to_string(info->min_args);
      if (info->max_args < 0)
        want = "at least " + want;
      else if (info->max_args != info->min_args)
        want += " to " + std::to_string(info->max_args);
      fail(name + "() takes " + want + " argument(s), got " + std::to_string(nargs));
    }
    return finish(std::move(n));
  }

  const std::string& s_;
  std::size_t pos_ = 0;
  int depth_ = 0;
};

// ---------------------------------------------------------------- evaluator

/// A scalar or one value per local atom.
struct Val {
  bool vec = false;
  double s = 0.0;
  std::vector<double> v;
  double at(std::size_t i) const { return vec ? v[i] : s; }
  std::size_t size() const { return v.size(); }
};

Val scalar(double x) {
  Val r;
  r.s = x;
  return r;
}
Val vector_of(std::vector<double> v) {
  Val r;
  r.vec = true;
  r.v = std::move(v);
  return r;
}

struct Ctx {
  Resolver& r;
  bool atom;  // atom-style evaluation
};

[[noreturn]] void fault(const Ctx& ctx, const std::string& msg) {
  if (ctx.atom) throw RunError(msg);
  throw EvalError(msg);
}

/// Element-wise combination of any number of operands.
template <class F>
Val map_n(const Ctx& ctx, const std::vector<Val>& args, F f) {
  std::size_t n = 0;
  bool any = false;
  for (const auto& a : args) {
    if (!a.vec) continue;
    if (any && a.size() != n) fault(ctx, "per-atom vectors of different lengths");
    n = a.size();
    any = true;
  }
  std::vector<double> x(args.size());
  if (!any) {
    for (std::size_t k = 0; k < args.size(); ++k)
      x[k] = args[k].s;
    return scalar(f(x.data()));
  }
  std::vector<double> out(n);
  for (std::size_t i = 0; i < n; ++i) {
    for (std::size_t k = 0; k < args.size(); ++k)
      x[k] = args[k].at(i);
    out[i] = f(x.data());
  }
  return vector_of(std::move(out));
}

/// Integer value of a step-like argument, saturated to +-1e15 (NaN gives 0).
long long ll(double x) {
  if (!(x == x)) return 0;
  return static_cast<long long>(std::max(-1.0e15, std::min(1.0e15, x)));
}

long long to_index(const Ctx& ctx, double x, const std::string& what) {
  if (!(std::fabs(x) < 9.0e15) || x != std::floor(x)) {
    throw EvalError(what + " must be an integer");
  }
  return static_cast<long long>(x);
}

double keyword_or_fail(Ctx& ctx, const std::string& key, const std::string& fn) {
  double v = 0.0;
  if (!ctx.r.keyword(key, v)) {
    throw EvalError(fn + "() needs the thermo keyword '" + key + "', which is not available");
  }
  return v;
}

Val eval(const Node& n, Ctx& ctx);

/// Indices and atom IDs are equal-style even inside atom-style formulas.
double eval_scalar(const Node& n, Ctx& ctx) {
  Ctx sub{ctx.r, false};
  return eval(n, sub).s;
}

[[noreturn]] void unknown_name(const std::string& name, Ctx& ctx) {
  std::vector<double> tmp;
  if (!ctx.atom && ctx.r.atom_vector(name, tmp)) {
    throw EvalError("'" + name + "' is a per-atom property: use it in an atom-style variable, or " + name +
                    "[ID] for the atom with that ID");
  }
  if (ctx.r.variable_exists(name)) {
    throw EvalError("unknown name '" + name + "'; to use the variable " + name + " write v_" + name);
  }
  auto known = ctx.r.keyword_names();
  for (auto& b : builtin_names())
    known.push_back(b);
  std::string msg = "unknown name '" + name + "' (not a thermo keyword, constant or " +
                    std::string(ctx.atom ? "per-atom property" : "variable reference") + ")";
  const std::string hint = did_you_mean(name, known);
  throw EvalError(hint.empty() ? msg : msg + "; " + hint);
}

Val eval_ref(const Node& n, Ctx& ctx) {
  Resolver& r = ctx.r;
  std::vector<long long> idx;
  for (const auto& k : n.kids) {
    idx.push_back(to_index(ctx, eval_scalar(*k, ctx), "an index"));
  }
  // in an atom-style formula c_ID[0] and f_ID[0] are the per-atom vector
  // itself (LIGGGHTS' f_Temp[0] of a property/atom)
  const bool vector_zero = ctx.atom && (n.ref == 'c' || n.ref == 'f') && idx.size() == 1 && idx[0] == 0;
  for (long long i : idx) {
    if (i < 1 && !vector_zero)
      throw EvalError("index " + std::to_string(i) + " of " + std::string(1, n.ref) + "_" + n.name +
                      " must be 1 or larger");
  }
  const std::string ref = std::string(1, n.ref) + "_" + n.name;
  std::vector<double> vals;
  if (n.ref == 'v') {
    if (!r.variable_exists(n.name)) {
      std::string msg = "unknown variable '" + n.name + "' in " + ref;
      const std::string hint = did_you_mean(n.name, r.variable_names());
      throw EvalError(hint.empty() ? msg : msg + "; " + hint);
    }
    const bool atom_var = r.variable_is_atom(n.name);
    if (idx.empty()) {
      if (!atom_var) return scalar(r.variable_value(n.name));
      if (!ctx.atom) {
        throw EvalError(ref + " is an atom-style variable; use " + ref +
                        "[ID] for one atom in an equal-style formula");
      }
      r.variable_atom(n.name, vals);
      return vector_of(std::move(vals));
    }
    if (!atom_var || idx.size() != 1) {
      throw EvalError(ref + "[i] needs an atom-style variable and one atom ID");
    }
    r.variable_atom(n.name, vals);
    return scalar(r.atom_element(vals, idx[0]));
  }
  const bool is_compute = n.ref == 'c' || n.ref == 'C';
  auto peratom = [&](int col) {
    if (is_compute)
      r.compute_peratom(n.name, col, vals);
    else
      r.fix_peratom(n.name, col, vals);
  };
  auto global = [&](int index) {
    return is_compute ? r.compute_value(n.name, index) : r.fix_value(n.name, index);
  };
  if (n.ref == 'C' || n.ref == 'F') {
    if (idx.empty()) throw EvalError(ref + " needs an atom ID: " + ref + "[ID] or " + ref + "[ID][column]");
    peratom(idx.size() > 1 ? static_cast<int>(idx[1]) : 0);
    return scalar(r.atom_element(vals, idx[0]));
  }
  if (idx.size() > 1) {
    throw EvalError(ref + "[i][j]: global arrays are not supported; use " +
                    std::string(1, static_cast<char>(n.ref - 32)) + "_" + n.name +
                    "[ID][column] for per-atom arrays");
  }
  const int index = idx.empty() ? 0 : static_cast<int>(idx[0]);
  if (!ctx.atom) return scalar(global(index));
  // Atom-style: a per-atom vector/column, else the global value.
  try {
    peratom(index);
    return vector_of(std::move(vals));
  } catch (const InputError& first) {
    try {
      return scalar(global(index));
    } catch (const InputError&) {
      throw first;
    }
  }
}

Val eval_func(const Node& n, Ctx& ctx) {
  std::vector<Val> a;
  a.reserve(n.kids.size());
  for (const auto& k : n.kids)
    a.push_back(eval(*k, ctx));
  const std::string fname = n.name + "()";
  auto map1 = [&](auto f) { return map_n(ctx, a, [&](const double* x) { return f(x[0]); }); };
  switch (n.fn) {
    case Fn::Sqrt:
      return map1([&](double x) {
        if (x < 0.0) fault(ctx, "sqrt() of a negative value (" + std::to_string(x) + ")");
        return std::sqrt(x);
      });
    case Fn::Exp:
      return map1([](double x) { return std::exp(x); });
    case Fn::Ln:
    case Fn::Log:
      return map1([&](double x) {
        if (x <= 0.0) fault(ctx, fname + " of a value that is not positive (" + std::to_string(x) + ")");
        return n.fn == Fn::Ln ? std::log(x) : std::log10(x);
      });
    case Fn::Abs:
      return map1([](double x) { return std::fabs(x); });
    case Fn::Sin:
      return map1([](double x) { return std::sin(x); });
    case Fn::Cos:
      return map1([](double x) { return std::cos(x); });
    case Fn::Tan:
      return map1([](double x) { return std::tan(x); });
    case Fn::Asin:
    case Fn::Acos:
      return map1([&](double x) {
        if (x < -1.0 || x > 1.0) fault(ctx, fname + " of a value outside [-1,1] (" + std::to_string(x) + ")");
        return n.fn == Fn::Asin ? std::asin(x) : std::acos(x);
      });
    case Fn::Atan:
      return map1([](double x) { return std::atan(x); });
    case Fn::Atan2:
      return map_n(ctx, a, [](const double* x) { return std::atan2(x[0], x[1]); });
    case Fn::Floor:
      return map1([](double x) { return std::floor(x); });
    case Fn::Ceil:
      return map1([](double x) { return std::ceil(x); });
    case Fn::Round:
      return map1([](double x) { return std::round(x); });
    case Fn::Min:
    case Fn::Max: {
      const std::size_t m = a.size();
      const bool mx = n.fn == Fn::Max;
      return map_n(ctx, a, [&](const double* x) {
        double r = x[0];
        for (std::size_t k = 1; k < m; ++k)
          r = mx ? std::max(r, x[k]) : std::min(r, x[k]);
        return r;
      });
    }
    case Fn::Ternary:
      return map_n(ctx, a, [](const double* x) { return x[0] != 0.0 ? x[1] : x[2]; });
    case Fn::Random:
    case Fn::Normal: {
      if (a[2].vec) fault(ctx, fname + ": the seed must be a single number");
      const long long seed = to_index(ctx, a[2].s, fname + " seed");
      if (seed <= 0) throw EvalError(fname + ": the seed must be a positive integer");
      auto& rng = n.rng[ctx.atom ? 1 : 0];
      if (!rng) rng = std::make_unique<expr_detail::Rng>(seed + (ctx.atom ? 7919LL * ctx.r.rank() : 0));
      const bool uni = n.fn == Fn::Random;
      auto draw = [&](double p, double q) {
        return uni ? p + (q - p) * rng->uniform() : p + q * rng->gaussian();
      };
      if (!ctx.atom) return scalar(draw(a[0].s, a[1].s));
      const std::size_t nl = a[0].vec ? a[0].size() : a[1].vec ? a[1].size() : ctx.r.nlocal();
      std::vector<double> out(nl);
      for (std::size_t i = 0; i < nl; ++i)
        out[i] = draw(a[0].at(i), a[1].at(i));
      return vector_of(std::move(out));
    }
    default:
      break;
  }
  // Functions of the current step.
  const double step = keyword_or_fail(ctx, "step", n.name);
  const long long istep = ll(step);
  switch (n.fn) {
    case Fn::Ramp: {
      const double b = keyword_or_fail(ctx, "__beginstep", n.name);
      const double e = keyword_or_fail(ctx, "__endstep", n.name);
      const double frac = e > b ? (step - b) / (e - b) : 0.0;
      return map_n(ctx, a, [&](const double* x) { return x[0] + (x[1] - x[0]) * frac; });
    }
    case Fn::Vdisplace:
    case Fn::Swiggle:
    case Fn::Cwiggle: {
      const double b = keyword_or_fail(ctx, "__beginstep", n.name);
      const double t = (step - b) * keyword_or_fail(ctx, "dt", n.name);
      const Fn f = n.fn;
      return map_n(ctx, a, [&](const double* x) {
        if (f == Fn::Vdisplace) return x[0] + x[1] * t;
        if (x[2] == 0.0) fault(ctx, fname + ": the period must not be zero");
        const double w = 2.0 * 3.14159265358979323846 / x[2];
        return f == Fn::Swiggle ? x[0] + x[1] * std::sin(w * t) : x[0] + x[1] * (1.0 - std::cos(w * t));
      });
    }
    case Fn::Stagger:
      return map_n(ctx, a, [&](const double* x) {
        const long long p = ll(x[0]), q = ll(x[1]);
        if (p <= 0 || q <= 0 || q >= p) fault(ctx, "stagger(x,y) needs x > y > 0");
        const long long lower = istep / p * p;
        return static_cast<double>(istep - lower < q ? lower + q : lower + p);
      });
    case Fn::Logfreq:
    case Fn::Logfreq2: {
      const bool two = n.fn == Fn::Logfreq2;
      return map_n(ctx, a, [&](const double* x) {
        const long long p = ll(x[0]), q = ll(x[1]), z = ll(x[2]);
        if (p <= 0 || q <= 0 || z <= 1 || (!two && q >= z))
          fault(ctx, fname + " needs x > 0, y > 0, z > 1" + std::string(two ? "" : ", y < z"));
        if (istep < p) return static_cast<double>(p);
        long long lower = p;
        while (lower < (1LL << 60) / z && istep >= z * lower)
          lower *= z;
        if (!two) {
          const long long multiple = istep / lower;
          return static_cast<double>(multiple < q ? (multiple + 1) * lower : lower * z);
        }
        const double delta = static_cast<double>(lower * (z - 1)) / static_cast<double>(q);
        const double count = std::floor((istep - lower) / delta) + 1.0;
        const double next = std::ceil(lower + count * delta);
        return std::min(next, static_cast<double>(lower * z));
      });
    }
    case Fn::Stride:
      return map_n(ctx, a, [&](const double* x) {
        const long long lo = ll(x[0]), hi = ll(x[1]), dz = ll(x[2]);
        if (lo < 0 || hi < lo || dz <= 0) fault(ctx, "stride(x,y,z) needs 0 <= x <= y and z > 0");
        if (istep < lo) return static_cast<double>(lo);
        const long long next = lo + ((istep - lo) / dz + 1) * dz;
        return next > hi ? 1.0e20 : static_cast<double>(next);
      });
    default:
      break;
  }
  throw EvalError("internal error: function " + fname + " has no evaluator");
}

Val eval(const Node& n, Ctx& ctx) {
  switch (n.kind) {
    case Node::Number:
      return scalar(n.value);
    case Node::Unary: {
      Val v = eval(*n.kids[0], ctx);
      std::vector<Val> a{std::move(v)};
      if (n.op == Op::Neg) return map_n(ctx, a, [](const double* x) { return -x[0]; });
      if (n.op == Op::Not) return map_n(ctx, a, [](const double* x) { return x[0] == 0.0 ? 1.0 : 0.0; });
      return std::move(a[0]);
    }
    case Node::Binary: {
      std::vector<Val> a;
      a.push_back(eval(*n.kids[0], ctx));
      a.push_back(eval(*n.kids[1], ctx));
      switch (n.op) {
        case Op::Add:
          return map_n(ctx, a, [](const double* x) { return x[0] + x[1]; });
        case Op::Sub:
          return map_n(ctx, a, [](const double* x) { return x[0] - x[1]; });
        case Op::Mul:
          return map_n(ctx, a, [](const double* x) { return x[0] * x[1]; });
        case Op::Div:
          return map_n(ctx, a, [&](const double* x) {
            if (x[1] == 0.0) fault(ctx, "division by zero");
            return x[0] / x[1];
          });
        case Op::Mod:
          return map_n(ctx, a, [&](const double* x) {
            if (x[1] == 0.0) fault(ctx, "modulo by zero");
            return std::fmod(x[0], x[1]);
          });
        case Op::Pow:
          return map_n(ctx, a, [&](const double* x) {
            if (x[0] == 0.0 && x[1] < 0.0) fault(ctx, "zero raised to a negative power");
            const double r = std::pow(x[0], x[1]);
            if (std::isnan(r) && !std::isnan(x[0]) && !std::isnan(x[1])) {
              fault(ctx, "negative number raised to a non-integer power");
            }
            return r;
          });
        case Op::Lt:
          return map_n(ctx, a, [](const double* x) { return x[0] < x[1] ? 1.0 : 0.0; });
        case Op::Le:
          return map_n(ctx, a, [](const double* x) { return x[0] <= x[1] ? 1.0 : 0.0; });
        case Op::Gt:
          return map_n(ctx, a, [](const double* x) { return x[0] > x[1] ? 1.0 : 0.0; });
        case Op::Ge:
          return map_n(ctx, a, [](const double* x) { return x[0] >= x[1] ? 1.0 : 0.0; });
        case Op::Eq:
          return map_n(ctx, a, [](const double* x) { return x[0] == x[1] ? 1.0 : 0.0; });
        case Op::Ne:
          return map_n(ctx, a, [](const double* x) { return x[0] != x[1] ? 1.0 : 0.0; });
        case Op::And:
          return map_n(ctx, a, [](const double* x) { return x[0] != 0.0 && x[1] != 0.0 ? 1.0 : 0.0; });
        case Op::Or:
          return map_n(ctx, a, [](const double* x) { return x[0] != 0.0 || x[1] != 0.0 ? 1.0 : 0.0; });
        case Op::Xor:
          return map_n(ctx, a, [](const double* x) { return (x[0] != 0.0) != (x[1] != 0.0) ? 1.0 : 0.0; });
        default:
          break;
      }
      throw EvalError("internal error: bad operator");
    }
    case Node::Func:
      return eval_func(n, ctx);
    case Node::Group:
      try {
        return scalar(ctx.r.group_function(n.name, n.raw));
      } catch (const EvalError&) {
        throw;
      } catch (const InputError& e) {
        throw EvalError(e.what());
      }
    case Node::IsFile: {
      std::ifstream f(n.raw[0]);
      return scalar(f.good() ? 1.0 : 0.0);
    }
    case Node::Name: {
      if (ctx.atom) {
        std::vector<double> v;
        if (ctx.r.atom_vector(n.name, v)) return vector_of(std::move(v));
      }
      double x = 0.0;
      bool found = false;
      try {
        found = ctx.r.keyword(n.name, x);
      } catch (const EvalError&) {
        throw;
      } catch (const InputError& e) {
        throw EvalError(e.what());
      }
      if (found) return scalar(x);
      unknown_name(n.name, ctx);
    }
    case Node::AtomValue: {
      const long long id = to_index(ctx, eval_scalar(*n.kids[0], ctx), "an atom ID");
      std::vector<double> v;
      if (!ctx.r.atom_vector(n.name, v)) {
        throw EvalError("'" + n.name + "[" + std::to_string(id) + "]': '" + n.name +
                        "' is not a per-atom property");
      }
      return scalar(ctx.r.atom_element(v, id));
    }
    case Node::Ref:
      if (n.ref == 'v') return eval_ref(n, ctx);  // nested variables report their own context
      try {
        return eval_ref(n, ctx);
      } catch (const EvalError&) {
        throw;
      } catch (const InputError& e) {
        throw EvalError(e.what());
      }
  }
  throw EvalError("internal error: bad node");
}

}  // namespace

// ---------------------------------------------------------------- Expression

Expression::Expression(const std::string& text) : text_(text) {
  Parser p(text_);
  root_ = p.parse();
}

double Expression::evaluate(Resolver& resolver) const {
  if (!root_) throw InputError("empty expression");
  Ctx ctx{resolver, false};
  try {
    Val v = eval(*root_, ctx);
    return v.s;
  } catch (const EvalError& e) {
    throw InputError(std::string(e.what()) + " in expression '" + text_ + "'");
  }
}

void Expression::evaluate_atom(Resolver& resolver, std::vector<double>& out) const {
  if (!root_) throw InputError("empty expression");
  Ctx ctx{resolver, true};
  try {
    Val v = eval(*root_, ctx);
    if (v.vec) {
      out = std::move(v.v);
    } else {
      out.assign(resolver.nlocal(), v.s);
    }
  } catch (const EvalError& e) {
    throw InputError(std::string(e.what()) + " in atom-style expression '" + text_ + "'");
  } catch (const RunError& e) {
    throw RunError(std::string(e.what()) + " in atom-style expression '" + text_ + "'");
  }
}

const std::vector<std::string>& expression_function_names() {
  static const std::vector<std::string> names = builtin_names();
  return names;
}

}  // namespace granary
