// Script variables (the `variable` command) and $-substitution.
//
// Styles: index, loop, universe, uloop, world (one partition), string, getenv,
// file, format, internal, equal, atom; `variable NAME delete` removes one.
// Variables work without an Engine: formulas look up thermo keywords, computes,
// fixes and per-atom data through the Resolver given to set_resolver().
#pragma once

#include <functional>
#include <map>
#include <memory>
#include <string>
#include <vector>

#include "core/expression.h"
#include "core/utils.h"

namespace granary {

/// Format a number with one C conversion ("%g", "%.6f", "%10.3e", "%d", ...);
/// text around the conversion is kept. Throws InputError for anything else.
std::string format_number(double value, const std::string& format);

class Variables {
 public:
  Variables();
  ~Variables();
  Variables(const Variables&) = delete;
  Variables& operator=(const Variables&) = delete;

  /// Lookups of formulas beyond variables (thermo keywords, computes, atoms, ...);
  /// null means formulas can use only numbers, functions and variables.
  void set_resolver(Resolver* external);
  /// Reads a whole file for file-style variables (Input installs one that reads
  /// on rank 0 and broadcasts). Returns false if the file cannot be read.
  using FileReader = std::function<bool(const std::string& path, std::string& contents)>;
  void set_file_reader(FileReader reader);

  /// The `variable` command: args = NAME STYLE VALUES...
  void set(const Args& args);
  /// `-var NAME V1 V2 ...` on the command line: an index variable that later
  /// `variable` commands for the same name leave alone.
  void set_command_line(const std::string& name, const Args& values);
  /// Set an internal-style variable (created if missing).
  void set_internal(const std::string& name, double value);

  bool find(const std::string& name) const;
  /// Style name of an existing variable ("index", "equal", ...); throws if unknown.
  std::string style(const std::string& name) const;
  bool is_atom(const std::string& name) const;
  std::vector<std::string> names() const;

  /// String value of any style except atom (equal-style formatted with %.15g).
  std::string retrieve(const std::string& name);
  /// Numeric value; string-valued styles must hold a number or a formula.
  /// Throws InputError naming the variable on failure.
  double compute_equal(const std::string& name);
  /// Atom-style values, one per local atom (other styles: their value repeated).
  void compute_atom(const std::string& name, std::vector<double>& out);

  /// The `next` command: advance each variable. Exhausted variables are
  /// removed; returns true if any was exhausted (the next `jump` is skipped).
  bool next(const Args& names);
  /// Remove a variable (no error if it does not exist).
  void remove(const std::string& name);

  /// Evaluate a formula now (immediate $(...) values); parsed forms are cached.
  double evaluate(const std::string& formula);
  void evaluate_atom(const std::string& formula, std::vector<double>& out);

  /// Replace $x, ${name}, $(formula) and $(formula:%fmt) outside quotes.
  std::string substitute(const std::string& text);

  /// Resolver that adds these variables to the external one (for formulas
  /// evaluated by other parts of the program).
  Resolver& resolver();

 private:
  struct Var;
  class Lookup;
  Var* get(const std::string& name);
  const Var* get(const std::string& name) const;
  Var& require(const std::string& name);
  [[noreturn]] void unknown(const std::string& name, const std::string& where) const;
  const Expression& cached(const std::string& formula);
  std::string immediate(const std::string& inner);

  std::map<std::string, std::unique_ptr<Var>> vars_;
  std::map<std::string, Expression> cache_;
  std::vector<std::string> active_;  // variables being evaluated (cycle detection)
  std::unique_ptr<Lookup> lookup_;
  Resolver* external_ = nullptr;
  FileReader reader_;
};

}  // namespace granary
