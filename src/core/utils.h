// Parsing of numbers and keywords in command arguments, with clear messages.
#pragma once

#include <cstdint>
#include <string>
#include <vector>

namespace granary {

using Args = std::vector<std::string>;

/// Parse a floating-point number; `what` names the argument in the message.
double parse_double(const std::string& word, const std::string& what);
/// Parse an integer (rejects fractions and trailing characters).
long long parse_int(const std::string& word, const std::string& what);
/// Parse yes/no (also on/off, true/false, 1/0).
bool parse_bool(const std::string& word, const std::string& what);

/// Throws InputError unless args.size() is in [lo, hi]; `usage` is the syntax line.
void require_args(const Args& args, std::size_t lo, std::size_t hi, const std::string& usage);

/// Parse a LAMMPS type range ("*", "2", "1*3", "*2", "3*") into [lo, hi] within [1, ntypes].
void parse_type_range(const std::string& word, int ntypes, int& lo, int& hi);

/// A number as printf's %g writes it (`digits` significant digits), for messages.
std::string format_number(double v, int digits = 6);
/// True when strtod reads the whole word as a number.
bool is_number(const std::string& word);
/// Join words with single spaces.
std::string join(const Args& words, std::size_t first = 0);

}  // namespace granary
