// Formulas of equal- and atom-style variables and of immediate $(...) values.
//
// A formula is parsed once into a tree and evaluated as often as needed. Names
// that are not part of the formula language (thermo keywords, computes, fixes,
// variables, per-atom properties, groups) are looked up through a Resolver, so
// the evaluator works without an Engine: the engine-backed Resolver lives in
// input.cpp, tests provide their own.
//
// Precedence, highest first: function calls and parentheses; ^ (right
// associative); unary - + !; * / %; + -; < <= > >=; == !=; &&; || |^.
// Atom-style evaluation works on whole per-atom vectors: every node of the tree
// yields either one number or one value per local atom.
#pragma once

#include <cstddef>
#include <memory>
#include <string>
#include <vector>

#include "core/utils.h"

namespace granary {

/// Everything a formula may refer to outside itself. The defaults of the
/// optional lookups throw InputError saying the quantity is not available.
class Resolver {
 public:
  virtual ~Resolver() = default;

  /// Thermo keyword ("step", "dt", "ke", ...; also "__beginstep"/"__endstep"
  /// for ramp()). Returns false when the name is not a keyword.
  virtual bool keyword(const std::string& name, double& value) = 0;
  /// Names offered in "did you mean" hints for unknown names.
  virtual std::vector<std::string> keyword_names() { return {}; }

  /// c_ID (index 0) or c_ID[i] (i >= 1).
  virtual double compute_value(const std::string& id, int index);
  /// f_ID (index 0) or f_ID[i] (i >= 1).
  virtual double fix_value(const std::string& id, int index);
  /// count(g), mass(g), xcm(g,x), bound(g,xmin), ... with optional region.
  virtual double group_function(const std::string& name, const Args& args);

  /// Per-atom property of the local atoms ("x", "vx", "mass", "radius", "id",
  /// ...); false when the name is not a per-atom property.
  virtual bool atom_vector(const std::string& name, std::vector<double>& out);
  /// Per-atom vector (col 0) or array column (col >= 1) of a compute / fix.
  virtual void compute_peratom(const std::string& id, int col, std::vector<double>& out);
  virtual void fix_peratom(const std::string& id, int col, std::vector<double>& out);
  /// Number of local atoms (the length of every per-atom vector).
  virtual std::size_t nlocal();
  /// The entry of a per-atom vector (one value per local atom) that belongs to
  /// the atom with global ID `id`, whichever rank owns it (collective).
  virtual double atom_element(const std::vector<double>& values, long long id);

  /// Variable references v_name.
  virtual bool variable_exists(const std::string& name);
  virtual bool variable_is_atom(const std::string& name);
  virtual double variable_value(const std::string& name);
  virtual void variable_atom(const std::string& name, std::vector<double>& out);
  virtual std::vector<std::string> variable_names() { return {}; }

  /// MPI rank: per-atom random numbers are seeded differently on each rank.
  virtual int rank() { return 0; }
};

namespace expr_detail {
struct Node;
}

/// A parsed formula. Copies share the parsed tree (and its random-number state).
class Expression {
 public:
  Expression() = default;
  /// Parse; throws InputError (with the text and the position) on bad syntax.
  explicit Expression(const std::string& text);

  const std::string& text() const { return text_; }
  bool empty() const { return !root_; }

  /// Equal-style value. Throws InputError naming the formula on failure.
  double evaluate(Resolver& resolver) const;
  /// Atom-style values, one per local atom (vectorised over the whole tree).
  /// Numeric faults for individual atoms (division by zero, ...) can happen on
  /// one rank only and are therefore raised as RunError.
  void evaluate_atom(Resolver& resolver, std::vector<double>& out) const;

 private:
  std::string text_;
  std::shared_ptr<const expr_detail::Node> root_;
};

/// Names of the built-in math functions, group functions and constants.
const std::vector<std::string>& expression_function_names();

}  // namespace granary
