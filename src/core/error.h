// Error types and helpers shared by every command and style.
#pragma once

#include <stdexcept>
#include <string>
#include <vector>

namespace granary {

/// Bad input in a script: thrown by commands and styles while a command is
/// executed. Input catches it, prefixes "file:line" and the include chain, and
/// stops the program with a non-zero exit after flushing what was written.
class InputError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

/// A condition found while a run is under way (particles lost, timestep too
/// large, a corrupt file). Raised on possibly only one rank; the top level turns
/// it into a clean MPI abort with the message printed.
class RunError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

/// "Did you mean X?" suggestion from a list of known names (edit distance),
/// empty when nothing is close.
std::string did_you_mean(const std::string& name, const std::vector<std::string>& known);

/// Edit distance between two words (Levenshtein), used for suggestions.
int edit_distance(const std::string& a, const std::string& b);

}  // namespace granary
