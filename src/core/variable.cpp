// Script variables and $-substitution; see variable.h.
#include "core/variable.h"

#include <algorithm>
#include <cctype>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <fstream>
#include <sstream>

#include "core/error.h"

namespace granary {

namespace {

enum class Style { Index, Loop, Universe, Uloop, World, String, Getenv, File, Format, Internal, Equal, Atom };

struct StyleName {
  const char* name;
  Style style;
};
const StyleName kStyles[] = {
    {"index", Style::Index},       {"loop", Style::Loop},   {"universe", Style::Universe},
    {"uloop", Style::Uloop},       {"world", Style::World}, {"string", Style::String},
    {"getenv", Style::Getenv},     {"file", Style::File},   {"format", Style::Format},
    {"internal", Style::Internal}, {"equal", Style::Equal}, {"atom", Style::Atom},
};

const char* style_name(Style s) {
  for (const auto& k : kStyles) {
    if (k.style == s) return k.name;
  }
  return "?";
}

/// Styles that a later `variable` command replaces (the others are kept, as in LAMMPS).
bool redefinable(Style s) {
  return s == Style::String || s == Style::Getenv || s == Style::Internal || s == Style::Equal ||
         s == Style::Atom;
}

bool advanceable(Style s) {
  return s == Style::Index || s == Style::Loop || s == Style::Universe || s == Style::Uloop ||
         s == Style::File;
}

std::string fmt15(double x) {
  char buf[64];
  std::snprintf(buf, sizeof(buf), "%.15g", x);
  return buf;
}

/// Whole-string number (surrounding blanks allowed).
bool to_number(const std::string& s, double& x) {
  const char* b = s.c_str();
  while (std::isspace(static_cast<unsigned char>(*b)))
    ++b;
  if (!*b) return false;
  char* e = nullptr;
  x = std::strtod(b, &e);
  if (e == b) return false;
  while (std::isspace(static_cast<unsigned char>(*e)))
    ++e;
  return *e == '\0';
}

long long loop_bound(const std::string& w, const std::string& what) {
  double x;
  if (!to_number(w, x) || x != std::floor(x)) {
    throw InputError("loop " + what + " must be an integer, got '" + w + "'");
  }
  if (std::fabs(x) > 1.0e15) throw InputError("loop " + what + " is too large: " + w);
  return static_cast<long long>(x);
}

bool local_reader(const std::string& path, std::string& contents) {
  std::ifstream f(path);
  if (!f) return false;
  std::ostringstream ss;
  ss << f.rdbuf();
  contents = ss.str();
  return true;
}

}  // namespace

struct Variables::Var {
  Style style = Style::Index;
  Args values;                      // index/universe/world/file strings; string, getenv; format: name, fmt
  std::size_t which = 0;            // current entry of values
  long long current = 1, last = 1;  // loop / uloop
  int pad = 0;                      // loop width when padded
  double number = 0.0;              // internal
  Expression expr;                  // equal / atom
  bool command_line = false;        // set with -var: script definitions leave it alone
};

// Resolver for formulas: variables here, everything else from the external resolver.
class Variables::Lookup : public Resolver {
 public:
  explicit Lookup(Variables& v) : v_(v) {}
  bool keyword(const std::string& name, double& value) override {
    return v_.external_ && v_.external_->keyword(name, value);
  }
  std::vector<std::string> keyword_names() override {
    return v_.external_ ? v_.external_->keyword_names() : std::vector<std::string>{};
  }
  double compute_value(const std::string& id, int index) override { return ext().compute_value(id, index); }
  double fix_value(const std::string& id, int index) override { return ext().fix_value(id, index); }
  double group_function(const std::string& name, const Args& args) override {
    return ext().group_function(name, args);
  }
  bool atom_vector(const std::string& name, std::vector<double>& out) override {
    return v_.external_ && v_.external_->atom_vector(name, out);
  }
  void compute_peratom(const std::string& id, int col, std::vector<double>& out) override {
    ext().compute_peratom(id, col, out);
  }
  void fix_peratom(const std::string& id, int col, std::vector<double>& out) override {
    ext().fix_peratom(id, col, out);
  }
  std::size_t nlocal() override { return v_.external_ ? v_.external_->nlocal() : 0; }
  double atom_element(const std::vector<double>& values, long long id) override {
    return ext().atom_element(values, id);
  }
  bool variable_exists(const std::string& name) override { return v_.find(name); }
  bool variable_is_atom(const std::string& name) override { return v_.is_atom(name); }
  double variable_value(const std::string& name) override { return v_.compute_equal(name); }
  void variable_atom(const std::string& name, std::vector<double>& out) override {
    v_.compute_atom(name, out);
  }
  std::vector<std::string> variable_names() override { return v_.names(); }
  int rank() override { return v_.external_ ? v_.external_->rank() : 0; }

 private:
  Resolver& ext() { return v_.external_ ? *v_.external_ : fallback_; }
  struct Nothing : Resolver {
    bool keyword(const std::string&, double&) override { return false; }
  } fallback_;
  Variables& v_;
};

Variables::Variables() : lookup_(std::make_unique<Lookup>(*this)), reader_(local_reader) {}
Variables::~Variables() = default;

void Variables::set_resolver(Resolver* external) {
  external_ = external;
}
void Variables::set_file_reader(FileReader reader) {
  reader_ = reader ? std::move(reader) : local_reader;
}
Resolver& Variables::resolver() {
  return *lookup_;
}

Variables::Var* Variables::get(const std::string& name) {
  auto it = vars_.find(name);
  return it == vars_.end() ? nullptr : it->second.get();
}
const Variables::Var* Variables::get(const std::string& name) const {
  auto it = vars_.find(name);
  return it == vars_.end() ? nullptr : it->second.get();
}

void Variables::unknown(const std::string& name, const std::string& where) const {
  std::string msg = "unknown variable '" + name + "'" + where;
  const std::string hint = did_you_mean(name, names());
  if (!hint.empty())
    msg += "; " + hint;
  else if (vars_.empty())
    msg += "; no variables are defined";
  throw InputError(msg);
}

Variables::Var& Variables::require(const std::string& name) {
  Var* v = get(name);
  if (!v) unknown(name, "");
  return *v;
}

bool Variables::find(const std::string& name) const {
  return get(name) != nullptr;
}

std::string Variables::style(const std::string& name) const {
  const Var* v = get(name);
  if (!v) unknown(name, "");
  return style_name(v->style);
}

bool Variables::is_atom(const std::string& name) const {
  const Var* v = get(name);
  return v && v->style == Style::Atom;
}

std::vector<std::string> Variables::names() const {
  std::vector<std::string> out;
  for (const auto& kv : vars_)
    out.push_back(kv.first);
  return out;
}

void Variables::remove(const std::string& name) {
  vars_.erase(name);
}

// ---------------------------------------------------------------- definition

void Variables::set(const Args& args) {
  const std::string usage =
      "expected: variable NAME STYLE VALUES... (style index, loop, string, equal, atom, "
      "getenv, file, format, internal, universe, uloop, world) or variable NAME delete";
  if (args.size() < 2) throw InputError("too few arguments; " + usage);
  const std::string& name = args[0];
  for (char c : name) {
    if (!std::isalnum(static_cast<unsigned char>(c)) && c != '_') {
      throw InputError("variable name '" + name + "' may contain only letters, digits and underscores");
    }
  }
  const std::string& sname = args[1];
  const Args vals(args.begin() + 2, args.end());
  if (sname == "delete") {
    if (!vals.empty()) throw InputError("variable NAME delete takes no further arguments");
    remove(name);
    return;
  }
  Style style = Style::Index;
  bool known = false;
  std::vector<std::string> all;
  for (const auto& k : kStyles) {
    all.emplace_back(k.name);
    if (sname == k.name) style = k.style, known = true;
  }
  if (!known) {
    all.emplace_back("delete");
    std::string msg = "unknown variable style '" + sname + "'";
    const std::string hint = did_you_mean(sname, all);
    throw InputError(hint.empty() ? msg + "; " + usage : msg + "; " + hint);
  }
  if (const Var* old = get(name)) {
    if (old->command_line) return;    // -var on the command line wins
    if (!redefinable(style)) return;  // index, loop, ... keep their current value
    if (old->style != style) {
      throw InputError("variable '" + name + "' already exists with style " + style_name(old->style) +
                       "; delete it first ('variable " + name + " delete') to redefine it as " + sname);
    }
  }
  auto need = [&](std::size_t lo, std::size_t hi, const std::string& form) {
    if (vals.size() < lo || vals.size() > hi) {
      std::string msg = "style " + sname + " expects: variable " + name + " " + sname + " " + form;
      if (vals.size() > hi) msg += " (enclose text with spaces in quotes)";
      throw InputError(msg);
    }
  };
  auto v = std::make_unique<Var>();
  v->style = style;
  switch (style) {
    case Style::Index:
    case Style::Universe:
      need(1, static_cast<std::size_t>(-1), "VALUE1 VALUE2 ...");
      v->values = vals;
      break;
    case Style::World:
      need(1, 1, "VALUE (one value per partition; Granary runs one partition)");
      v->values = vals;
      break;
    case Style::Loop:
    case Style::Uloop: {
      need(1, 3, "N [pad] or N1 N2 [pad]");
      Args nums = vals;
      const bool pad = nums.back() == "pad";
      if (pad) nums.pop_back();
      if (nums.empty() || nums.size() > 2)
        throw InputError("style loop expects: variable NAME loop N [pad] or N1 N2 [pad]");
      long long first = 1, last;
      if (nums.size() == 1) {
        last = loop_bound(nums[0], "count N");
        if (last < 1) throw InputError("loop count N must be at least 1, got " + nums[0]);
      } else {
        first = loop_bound(nums[0], "start N1");
        last = loop_bound(nums[1], "end N2");
        if (first > last || last < 0) {
          throw InputError("loop N1 N2 needs N1 <= N2 and N2 >= 0, got " + nums[0] + " " + nums[1]);
        }
      }
      v->current = first;
      v->last = last;
      if (pad) v->pad = static_cast<int>(std::to_string(last).size());
      break;
    }
    case Style::String:
      need(1, 1, "TEXT");
      v->values = {substitute(vals[0])};
      break;
    case Style::Getenv:
      need(1, 1, "ENVIRONMENT_VARIABLE");
      v->values = vals;
      break;
    case Style::File: {
      need(1, 1, "FILENAME");
      std::string text;
      if (!reader_(vals[0], text))
        throw InputError("cannot read file '" + vals[0] + "' for file-style variable " + name);
      std::istringstream in(text);
      std::string line;
      while (std::getline(in, line)) {
        const auto hash = line.find('#');
        if (hash != std::string::npos) line.erase(hash);
        std::istringstream words(line);
        std::string first;
        if (words >> first) v->values.push_back(first);
      }
      if (v->values.empty()) throw InputError("file '" + vals[0] + "' holds no values for variable " + name);
      break;
    }
    case Style::Format:
      need(2, 2, "VARIABLE_NAME FORMAT (e.g. variable f format x %.6f)");
      format_number(0.0, vals[1]);  // validate now
      v->values = vals;
      break;
    case Style::Internal:
      need(1, 1, "NUMBER");
      if (!to_number(vals[0], v->number))
        throw InputError("style internal needs a number, got '" + vals[0] + "'");
      break;
    case Style::Equal:
    case Style::Atom: {
      if (vals.empty())
        throw InputError("style " + sname + " expects: variable " + name + " " + sname + " FORMULA");
      try {
        v->expr = Expression(join(vals));
      } catch (const InputError& e) {
        throw InputError("variable " + name + ": " + e.what());
      }
      break;
    }
  }
  vars_[name] = std::move(v);
}

void Variables::set_command_line(const std::string& name, const Args& values) {
  Args args{name, "index"};
  args.insert(args.end(), values.begin(), values.end());
  remove(name);
  set(args);
  vars_[name]->command_line = true;
}

void Variables::set_internal(const std::string& name, double value) {
  Var* v = get(name);
  if (v && v->style != Style::Internal) {
    throw InputError("variable '" + name + "' has style " + std::string(style_name(v->style)) +
                     ", not internal");
  }
  if (!v) {
    auto nv = std::make_unique<Var>();
    nv->style = Style::Internal;
    v = nv.get();
    vars_[name] = std::move(nv);
  }
  v->number = value;
}

// ---------------------------------------------------------------- values

std::string Variables::retrieve(const std::string& name) {
  Var& v = require(name);
  switch (v.style) {
    case Style::Index:
    case Style::Universe:
    case Style::World:
    case Style::File:
      return v.values[v.which];
    case Style::Loop:
    case Style::Uloop: {
      std::string s = std::to_string(v.current);
      if (v.pad > static_cast<int>(s.size())) s.insert(0, v.pad - s.size(), '0');
      return s;
    }
    case Style::String:
      return v.values[0];
    case Style::Getenv: {
      const char* e = std::getenv(v.values[0].c_str());
      return e ? e : "";
    }
    case Style::Format: {
      const std::string fmt = v.values[1];
      return format_number(compute_equal(v.values[0]), fmt);
    }
    case Style::Internal:
      return fmt15(v.number);
    case Style::Equal:
      return fmt15(compute_equal(name));
    case Style::Atom:
      throw InputError("atom-style variable '" + name +
                       "' has one value per atom and cannot be substituted as text");
  }
  return "";
}

double Variables::compute_equal(const std::string& name) {
  Var& v = require(name);
  if (std::find(active_.begin(), active_.end(), name) != active_.end()) {
    std::string chain;
    for (const auto& a : active_)
      chain += a + " -> ";
    throw InputError("variable '" + name + "' refers to itself (" + chain + name + ")");
  }
  struct Guard {
    std::vector<std::string>& a;
    ~Guard() { a.pop_back(); }
  };
  active_.push_back(name);
  Guard guard{active_};
  try {
    switch (v.style) {
      case Style::Equal:
        return v.expr.evaluate(*lookup_);
      case Style::Internal:
        return v.number;
      case Style::Atom:
        throw InputError("it is atom-style; use v_" + name + "[ID] for the value of one atom");
      default: {
        const std::string s = retrieve(name);
        double x;
        if (to_number(s, x)) return x;
        try {
          return cached(s).evaluate(*lookup_);
        } catch (const InputError&) {
          throw InputError("its value '" + s + "' is not a number");
        }
      }
    }
  } catch (const RunError&) {
    throw;
  } catch (const InputError& e) {
    throw InputError("variable " + name + ": " + e.what());
  }
}

void Variables::compute_atom(const std::string& name, std::vector<double>& out) {
  Var& v = require(name);
  if (v.style != Style::Atom) {
    out.assign(lookup_->nlocal(), compute_equal(name));
    return;
  }
  if (std::find(active_.begin(), active_.end(), name) != active_.end()) {
    throw InputError("variable '" + name + "' refers to itself");
  }
  struct Guard {
    std::vector<std::string>& a;
    ~Guard() { a.pop_back(); }
  };
  active_.push_back(name);
  Guard guard{active_};
  try {
    v.expr.evaluate_atom(*lookup_, out);
  } catch (const RunError& e) {
    throw RunError("variable " + name + ": " + e.what());
  } catch (const InputError& e) {
    throw InputError("variable " + name + ": " + e.what());
  }
}

bool Variables::next(const Args& names) {
  if (names.empty()) throw InputError("expected: next VARIABLE [VARIABLE ...]");
  for (const auto& n : names) {
    const Var& v = require(n);
    if (!advanceable(v.style)) {
      throw InputError("variable '" + n + "' has style " + std::string(style_name(v.style)) +
                       "; next works with index, loop, file, universe and uloop variables");
    }
  }
  bool exhausted = false;
  for (const auto& n : names) {
    Var* v = get(n);
    if (!v) continue;  // listed twice and already exhausted
    bool done;
    if (v->style == Style::Loop || v->style == Style::Uloop) {
      done = v->current >= v->last;
      if (!done) ++v->current;
    } else {
      done = v->which + 1 >= v->values.size();
      if (!done) ++v->which;
    }
    if (done) {
      remove(n);
      exhausted = true;
    }
  }
  return exhausted;
}

// ---------------------------------------------------------------- formulas

const Expression& Variables::cached(const std::string& formula) {
  auto it = cache_.find(formula);
  if (it != cache_.end()) return it->second;
  if (cache_.size() > 2000) cache_.clear();
  Expression e(formula);
  return cache_.emplace(formula, std::move(e)).first->second;
}

double Variables::evaluate(const std::string& formula) {
  return cached(formula).evaluate(*lookup_);
}

void Variables::evaluate_atom(const std::string& formula, std::vector<double>& out) {
  cached(formula).evaluate_atom(*lookup_, out);
}

std::string Variables::immediate(const std::string& inner) {
  std::string formula = inner, fmt = "%.15g";
  const auto colon = inner.rfind(':');
  if (colon != std::string::npos) {
    std::size_t p = colon + 1;
    while (p < inner.size() && std::isspace(static_cast<unsigned char>(inner[p])))
      ++p;
    if (p < inner.size() && inner[p] == '%') {
      formula = inner.substr(0, colon);
      fmt = inner.substr(p);
      while (!fmt.empty() && std::isspace(static_cast<unsigned char>(fmt.back())))
        fmt.pop_back();
    }
  }
  return format_number(evaluate(formula), fmt);
}

std::string Variables::substitute(const std::string& text) {
  std::string out;
  out.reserve(text.size());
  int quote = 0;  // 1 single, 2 double, 3 triple
  std::size_t i = 0;
  const std::size_t n = text.size();
  while (i < n) {
    const char c = text[i];
    const bool triple = text.compare(i, 3, "\"\"\"") == 0;
    if (quote == 0) {
      if (triple) {
        quote = 3;
        out += "\"\"\"";
        i += 3;
        continue;
      }
      if (c == '"') {
        quote = 2;
      } else if (c == '\'') {
        quote = 1;
      } else if (c == '$') {
        if (i + 1 >= n || std::isspace(static_cast<unsigned char>(text[i + 1]))) {
          throw InputError("'$' must be followed by a variable name: $x, ${name} or $(formula)");
        }
        const char d = text[i + 1];
        if (d == '{') {
          const auto close = text.find('}', i + 2);
          if (close == std::string::npos)
            throw InputError("missing '}' after '${' in '" + text.substr(i, 30) + "'");
          const std::string name = text.substr(i + 2, close - i - 2);
          if (name.empty()) throw InputError("empty variable name in '${}'");
          if (!find(name)) unknown(name, " in '${" + name + "}'");
          out += retrieve(name);
          i = close + 1;
        } else if (d == '(') {
          int depth = 0;
          std::size_t j = i + 1;
          for (; j < n; ++j) {
            if (text[j] == '(') ++depth;
            if (text[j] == ')' && --depth == 0) break;
          }
          if (j >= n) throw InputError("missing ')' to close '$(' in '" + text.substr(i, 40) + "'");
          out += immediate(text.substr(i + 2, j - i - 2));
          i = j + 1;
        } else {
          const std::string name(1, d);
          if (!find(name)) unknown(name, " in '$" + name + "' (use ${...} for longer names)");
          out += retrieve(name);
          i += 2;
        }
        continue;
      }
    } else if (quote == 3) {
      if (triple) {
        quote = 0;
        out += "\"\"\"";
        i += 3;
        continue;
      }
    } else if ((quote == 2 && c == '"') || (quote == 1 && c == '\'')) {
      quote = 0;
    }
    out += c;
    ++i;
  }
  return out;
}

// ---------------------------------------------------------------- number formats

std::string format_number(double value, const std::string& format) {
  // Locate exactly one conversion; "%%" is a literal percent sign.
  std::size_t conv = std::string::npos, end = 0;
  for (std::size_t i = 0; i < format.size(); ++i) {
    if (format[i] != '%') continue;
    if (i + 1 < format.size() && format[i + 1] == '%') {
      ++i;
      continue;
    }
    if (conv != std::string::npos) {
      throw InputError("format '" + format +
                       "' has more than one '%' conversion; use exactly one, e.g. %.6g");
    }
    conv = i;
    std::size_t j = i + 1;
    while (j < format.size() && std::string("-+ #0").find(format[j]) != std::string::npos)
      ++j;
    int width = 0, prec = 0;
    while (j < format.size() && std::isdigit(static_cast<unsigned char>(format[j]))) {
      width = std::min(width * 10 + (format[j++] - '0'), 100000);
    }
    if (j < format.size() && format[j] == '.') {
      ++j;
      while (j < format.size() && std::isdigit(static_cast<unsigned char>(format[j]))) {
        prec = std::min(prec * 10 + (format[j++] - '0'), 100000);
      }
    }
    if (j >= format.size() || std::string("eEfFgGaAdi").find(format[j]) == std::string::npos) {
      throw InputError("format '" + format + "' is not a number format; use e.g. %g, %.6f, %12.4e or %d");
    }
    if (width > 500 || prec > 500) throw InputError("format '" + format + "' asks for too many characters");
    end = j;
  }
  if (conv == std::string::npos) {
    throw InputError("format '" + format + "' has no '%' conversion; use e.g. %g, %.6f or %d");
  }
  const char type = format[end];
  std::string spec = format;
  char buf[1100];
  if (type == 'd' || type == 'i') {
    spec.insert(end, "ll");
    const double r = std::round(value);
    const long long iv = std::fabs(r) < 9.2e18 ? static_cast<long long>(r) : 0;
    std::snprintf(buf, sizeof(buf), spec.c_str(), iv);
  } else {
    std::snprintf(buf, sizeof(buf), spec.c_str(), value);
  }
  return buf;
}

}  // namespace granary
