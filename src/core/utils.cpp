#include "core/utils.h"

#include <cerrno>
#include <cmath>
#include <cstdio>
#include <cstdlib>

#include "core/error.h"

namespace granary {

double parse_double(const std::string& word, const std::string& what) {
  const char* s = word.c_str();
  char* end = nullptr;
  errno = 0;
  const double value = std::strtod(s, &end);
  if (word.empty() || end == s || *end != '\0' || errno == ERANGE || !std::isfinite(value)) {
    throw InputError("expected a number for " + what + ", got '" + word + "'");
  }
  return value;
}

long long parse_int(const std::string& word, const std::string& what) {
  const char* s = word.c_str();
  char* end = nullptr;
  errno = 0;
  const long long value = std::strtoll(s, &end, 10);
  if (word.empty() || end == s || *end != '\0' || errno == ERANGE) {
    // Accept integral values written as floats ("1e4", "100.0") as LAMMPS does for counts.
    char* fend = nullptr;
    const double d = std::strtod(s, &fend);
    if (!word.empty() && fend != s && *fend == '\0' && std::isfinite(d) && d == std::floor(d) &&
        std::fabs(d) < 9.0e18) {
      return static_cast<long long>(d);
    }
    throw InputError("expected an integer for " + what + ", got '" + word + "'");
  }
  return value;
}

bool parse_bool(const std::string& word, const std::string& what) {
  if (word == "yes" || word == "on" || word == "true" || word == "1") return true;
  if (word == "no" || word == "off" || word == "false" || word == "0") return false;
  throw InputError("expected yes or no for " + what + ", got '" + word + "'");
}

void require_args(const Args& args, std::size_t lo, std::size_t hi, const std::string& usage) {
  if (args.size() < lo || args.size() > hi) {
    std::string count = lo == hi ? std::to_string(lo)
                                 : (hi > 1000 ? "at least " + std::to_string(lo)
                                              : std::to_string(lo) + " to " + std::to_string(hi));
    throw InputError("wrong number of arguments (" + std::to_string(args.size()) + ", expected " + count +
                     "); usage: " + usage);
  }
}

void parse_type_range(const std::string& word, int ntypes, int& lo, int& hi) {
  const auto star = word.find('*');
  if (star == std::string::npos) {
    lo = hi = static_cast<int>(parse_int(word, "a type"));
  } else {
    const std::string a = word.substr(0, star), b = word.substr(star + 1);
    lo = a.empty() ? 1 : static_cast<int>(parse_int(a, "a type range"));
    hi = b.empty() ? ntypes : static_cast<int>(parse_int(b, "a type range"));
  }
  if (lo < 1 || hi > ntypes || lo > hi) {
    throw InputError("type range '" + word + "' is outside 1.." + std::to_string(ntypes));
  }
}

std::string join(const Args& words, std::size_t first) {
  std::string out;
  for (std::size_t i = first; i < words.size(); ++i) {
    if (i > first) out += ' ';
    out += words[i];
  }
  return out;
}

std::string format_number(double v, int digits) {
  char buf[64];
  std::snprintf(buf, sizeof buf, "%.*g", digits, v);
  return buf;
}

bool is_number(const std::string& word) {
  if (word.empty()) return false;
  char* end = nullptr;
  std::strtod(word.c_str(), &end);
  return end && *end == '\0';
}

}  // namespace granary
