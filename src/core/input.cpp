// The script reader; see input.h.
#include "core/input.h"

#include <mpi.h>

#include <algorithm>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <functional>
#include <new>
#include <sstream>

#include "core/engine.h"
#include "core/error.h"
#include "core/expression.h"
#include "core/logger.h"
#include "core/stop_signal.h"
#include "core/variable.h"

namespace granary {

// ---------------------------------------------------------------- line handling

namespace script {

namespace {
bool blank(char c) {
  return c == ' ' || c == '\t' || c == '\n' || c == '\r' || c == '\v' || c == '\f';
}
bool triple_at(const std::string& s, std::size_t i) {
  return s.compare(i, 3, "\"\"\"") == 0;
}
}  // namespace

int count_triple_quotes(const std::string& text) {
  int n = 0;
  for (std::size_t p = text.find("\"\"\""); p != std::string::npos; p = text.find("\"\"\"", p + 3))
    ++n;
  return n;
}

std::string strip_comment(const std::string& line) {
  int quote = 0;  // 1 single, 2 double, 3 triple
  for (std::size_t i = 0; i < line.size(); ++i) {
    const char c = line[i];
    if (quote == 0) {
      if (triple_at(line, i)) {
        quote = 3;
        i += 2;
      } else if (c == '"') {
        quote = 2;
      } else if (c == '\'') {
        quote = 1;
      } else if (c == '#') {
        return line.substr(0, i);
      }
    } else if (quote == 3) {
      if (triple_at(line, i)) {
        quote = 0;
        i += 2;
      }
    } else if ((quote == 2 && c == '"') || (quote == 1 && c == '\'')) {
      quote = 0;
    }
  }
  return line;
}

Args split_words(const std::string& line) {
  Args out;
  const std::size_t n = line.size();
  std::size_t i = 0;
  auto excerpt = [&](std::size_t from) {
    std::string s = line.substr(from, 40);
    for (char& c : s) {
      if (c == '\n') c = ' ';
    }
    return s + (from + 40 < n ? "..." : "");
  };
  for (;;) {
    while (i < n && blank(line[i]))
      ++i;
    if (i >= n) break;
    std::size_t start = i, close, after;
    if (triple_at(line, i)) {
      close = line.find("\"\"\"", i + 3);
      if (close == std::string::npos) throw InputError("unclosed triple quote \"\"\" in: " + excerpt(start));
      start = i + 3;
      after = close + 3;
    } else if (line[i] == '"' || line[i] == '\'') {
      close = line.find(line[i], i + 1);
      if (close == std::string::npos) {
        throw InputError(std::string("unclosed quote ") + line[i] + " in: " + excerpt(start));
      }
      start = i + 1;
      after = close + 1;
    } else {
      while (i < n && !blank(line[i]))
        ++i;
      out.push_back(line.substr(start, i - start));
      continue;
    }
    if (after < n && !blank(line[after])) {
      throw InputError("a closing quote must be followed by a blank: " + excerpt(start > 3 ? start - 3 : 0));
    }
    out.push_back(line.substr(start, close - start));
    i = after;
  }
  return out;
}

bool read_command(std::istream& in, std::string& command, int& lines) {
  command.clear();
  lines = 0;
  std::string line;
  while (std::getline(in, line)) {
    ++lines;
    if (!line.empty() && line.back() == '\r') line.pop_back();
    command += line;
    if (count_triple_quotes(command) % 2 == 1) {  // inside """: keep the line break
      command += '\n';
      continue;
    }
    const auto last = command.find_last_not_of(" \t\r\n\v\f");
    if (last != std::string::npos && command[last] == '&') {
      command.erase(last);
      continue;
    }
    return true;
  }
  return lines > 0;  // input ended inside a continued command
}

// ---------------------------------------------------------------- if-command Booleans

namespace {

constexpr int kMaxBoolDepth = 250;

std::string snippet(const std::string& s, std::size_t pos) {
  std::string rest = s.substr(std::min(pos, s.size()), 24);
  if (pos + 24 < s.size()) rest += "...";
  return rest;
}

struct BVal {
  bool is_str = false;
  double num = 0.0;
  std::string str;
};

class BoolParser {
 public:
  explicit BoolParser(const std::string& text) : s_(text) {}

  bool run() {
    BVal v = parse_or();
    skip_ws();
    if (pos_ < s_.size()) fail("unexpected '" + snippet(s_, pos_) + "'");
    return truth(v);
  }

 private:
  [[noreturn]] void fail(const std::string& what) const {
    throw InputError("bad Boolean expression '" + s_ + "': " + what);
  }
  void skip_ws() {
    while (pos_ < s_.size() && std::isspace(static_cast<unsigned char>(s_[pos_])))
      ++pos_;
  }
  bool accept(const char* tok) {
    skip_ws();
    const std::size_t n = std::char_traits<char>::length(tok);
    if (s_.compare(pos_, n, tok) != 0) return false;
    pos_ += n;
    return true;
  }
  double truth(const BVal& v) const {
    if (!v.is_str) return v.num != 0.0;
    if (v.str == "yes" || v.str == "on" || v.str == "true") return 1.0;
    if (v.str == "no" || v.str == "off" || v.str == "false") return 0.0;
    fail("'" + v.str + "' is a string, not a true/false value" + arithmetic_hint(v.str));
  }
  static std::string arithmetic_hint(const std::string& s) {
    if (s.find_first_of("+-*/^%") != std::string::npos) {
      return " (arithmetic is not evaluated here: write $(" + s + ") to compute it)";
    }
    return "";
  }
  static BVal num(double x) {
    BVal b;
    b.num = x;
    return b;
  }

  BVal parse_or() {
    BVal a = parse_and();
    for (;;) {
      if (accept("||")) {
        BVal b = parse_and();
        a = num(truth(a) || truth(b) ? 1.0 : 0.0);
      } else if (accept("|^")) {
        BVal b = parse_and();
        a = num((truth(a) != 0.0) != (truth(b) != 0.0) ? 1.0 : 0.0);
      } else {
        return a;
      }
    }
  }
  BVal parse_and() {
    BVal a = parse_eq();
    while (accept("&&")) {
      BVal b = parse_eq();
      a = num(truth(a) && truth(b) ? 1.0 : 0.0);
    }
    return a;
  }
  BVal compare(const BVal& a, const BVal& b, const std::string& op) {
    int c;
    if (a.is_str != b.is_str) {
      const std::string& str = a.is_str ? a.str : b.str;
      fail("cannot compare a number with the string '" + str + "' using " + op + arithmetic_hint(str));
    }
    if (a.is_str)
      c = a.str.compare(b.str);
    else
      c = a.num < b.num ? -1 : (a.num > b.num ? 1 : 0);
    bool r = false;
    if (op == "==")
      r = c == 0;
    else if (op == "!=")
      r = c != 0;
    else if (op == "<")
      r = c < 0;
    else if (op == "<=")
      r = c <= 0;
    else if (op == ">")
      r = c > 0;
    else
      r = c >= 0;
    return num(r ? 1.0 : 0.0);
  }
  BVal parse_eq() {
    BVal a = parse_rel();
    for (;;) {
      const char* op = accept("==") ? "==" : accept("!=") ? "!=" : nullptr;
      if (!op) return a;
      BVal b = parse_rel();
      a = compare(a, b, op);
    }
  }
  BVal parse_rel() {
    BVal a = parse_not();
    for (;;) {
      const char* op = accept("<=")   ? "<="
                       : accept(">=") ? ">="
                       : accept("<")  ? "<"
                       : accept(">")  ? ">"
                                      : nullptr;
      if (!op) return a;
      BVal b = parse_not();
      a = compare(a, b, op);
    }
  }
  BVal parse_not() {
    if (++depth_ > kMaxBoolDepth) fail("nested too deeply");
    BVal r;
    skip_ws();
    if (pos_ < s_.size() && s_[pos_] == '!' && s_.compare(pos_, 2, "!=") != 0) {
      ++pos_;
      r = num(truth(parse_not()) ? 0.0 : 1.0);
    } else {
      r = parse_operand();
    }
    --depth_;
    return r;
  }
  BVal parse_operand() {
    skip_ws();
    if (pos_ >= s_.size()) fail("a value is missing at the end");
    if (s_[pos_] == '(') {
      ++pos_;
      BVal v = parse_or();
      skip_ws();
      if (pos_ >= s_.size() || s_[pos_] != ')') fail("missing ')'");
      ++pos_;
      return v;
    }
    const std::size_t start = pos_;
    while (pos_ < s_.size() && !std::isspace(static_cast<unsigned char>(s_[pos_])) &&
           std::string("()<>=!&|").find(s_[pos_]) == std::string::npos) {
      ++pos_;
    }
    if (pos_ == start) fail("a value is missing before '" + snippet(s_, pos_) + "'");
    const std::string word = s_.substr(start, pos_ - start);
    char* endp = nullptr;
    const double x = std::strtod(word.c_str(), &endp);
    const char c0 = word[0];
    const bool numeric_start =
        std::isdigit(static_cast<unsigned char>(c0)) || c0 == '.' || c0 == '-' || c0 == '+';
    if (numeric_start && endp && *endp == '\0') return num(x);
    BVal b;
    b.is_str = true;
    b.str = word;
    return b;
  }

  const std::string& s_;
  std::size_t pos_ = 0;
  int depth_ = 0;
};

}  // namespace

bool evaluate_boolean(const std::string& text) {
  if (text.size() > 100000) throw InputError("Boolean expression is too long");
  BoolParser p(text);
  return p.run();
}

}  // namespace script

// ---------------------------------------------------------------- errors

namespace {

/// An error from a command, tagged with the (innermost) command's name.
class CommandError : public InputError {
 public:
  CommandError(std::string cmd, const std::string& msg) : InputError(msg), command(std::move(cmd)) {}
  std::string command;
};

/// An error that already names its file, line and include chain.
class ScriptError : public InputError {
 public:
  using InputError::InputError;
};
class LocatedRunError : public RunError {
 public:
  using RunError::RunError;
};

std::string first_word(const std::string& text) {
  std::istringstream ss(text);
  std::string w;
  ss >> w;
  return w;
}

}  // namespace

// ---------------------------------------------------------------- engine lookups

class Input::EngineLookup : public Resolver {
 public:
  explicit EngineLookup(Engine& e) : e_(e) {}
  bool keyword(const std::string& name, double& value) override {
    bool found = false;
    value = e_.thermo_keyword(name, found);
    return found;
  }
  std::vector<std::string> keyword_names() override {
    return {"step",    "elapsed", "elaplong", "dt",    "time",   "cpu",    "tpcpu",   "spcpu",
            "atoms",   "temp",    "press",    "pe",    "ke",     "etotal", "erotate", "vol",
            "density", "lx",      "ly",       "lz",    "xlo",    "xhi",    "ylo",     "yhi",
            "zlo",     "zhi",     "fmax",     "fnorm", "nbuild", "ndanger"};
  }
  double compute_value(const std::string& id, int index) override { return e_.compute_value(id, index); }
  double fix_value(const std::string& id, int index) override { return e_.fix_value(id, index); }
  double group_function(const std::string& name, const Args& args) override {
    return e_.group_function(name, args);
  }
  bool atom_vector(const std::string& name, std::vector<double>& out) override {
    return e_.atom_vector(name, out);
  }
  void compute_peratom(const std::string& id, int col, std::vector<double>& out) override {
    e_.compute_peratom(id, col, out);
  }
  void fix_peratom(const std::string& id, int col, std::vector<double>& out) override {
    e_.fix_peratom(id, col, out);
  }
  std::size_t nlocal() override {
    std::vector<double> ids;
    e_.atom_vector("id", ids);
    return ids.size();
  }
  double atom_element(const std::vector<double>& values, long long id) override {
    std::vector<double> ids;
    e_.atom_vector("id", ids);
    double buf[2] = {0.0, 0.0};
    for (std::size_t i = 0; i < ids.size() && i < values.size(); ++i) {
      if (static_cast<long long>(ids[i]) == id) {
        buf[0] += values[i];
        buf[1] += 1.0;
      }
    }
    MPI_Allreduce(MPI_IN_PLACE, buf, 2, MPI_DOUBLE, MPI_SUM, e_.world);
    if (buf[1] == 0.0) throw InputError("there is no atom with ID " + std::to_string(id));
    return buf[0] / buf[1];
  }
  int rank() override { return e_.rank; }

 private:
  Engine& e_;
};

// ---------------------------------------------------------------- Input

struct Input::Source {
  std::string name;
  std::unique_ptr<std::ifstream> file;  // rank 0, when reading a file
  std::istream* in = nullptr;           // rank 0 only
  bool rewindable = false;              // a file (jump SELF can start it again)
  int line = 0;                         // physical lines consumed
  int cmd_line = 0;                     // first line of the current command
};

Input::Input(Engine& engine)
    : engine_(engine),
      variables_(std::make_unique<Variables>()),
      lookup_(std::make_unique<EngineLookup>(engine)) {
  variables_->set_resolver(lookup_.get());
  variables_->set_file_reader(
      [this](const std::string& path, std::string& contents) { return read_file(path, contents); });
}

Input::~Input() = default;

Variables& Input::variables() {
  return *variables_;
}

void Input::set_echo(bool screen, bool log) {
  echo_screen_ = screen;
  echo_log_ = log;
}

std::string Input::substitute(const std::string& text) {
  return variables_->substitute(text);
}

void Input::request_quit(int status) {
  quit_ = true;
  quit_status_ = status;
}

std::string Input::location() const {
  if (sources_.empty()) return "";
  std::string out = sources_.back()->name + ":" + std::to_string(sources_.back()->cmd_line);
  for (std::size_t k = sources_.size() - 1; k-- > 0;) {
    out += " (included from " + sources_[k]->name + ":" + std::to_string(sources_[k]->cmd_line) + ")";
  }
  return out;
}

namespace {
/// "file:line: cmd: message" plus one "  included from" line per outer file.
std::string format_error(const std::vector<std::string>& frames, const std::string& cmd,
                         const std::string& msg) {
  std::string out = frames.empty() ? "" : frames.back() + ": ";
  // the command's name once: a message that already starts with it ("replicate: ...",
  // "fix ID style: ...") gets no second one
  const bool named = !cmd.empty() && msg.size() > cmd.size() && msg.compare(0, cmd.size(), cmd) == 0 &&
                     (msg[cmd.size()] == ':' || msg[cmd.size()] == ' ');
  if (!cmd.empty() && !named) out += cmd + ": ";
  out += msg;
  for (std::size_t k = frames.size() > 0 ? frames.size() - 1 : 0; k-- > 0;)
    out += "\n  included from " + frames[k];
  return out;
}
}  // namespace

bool Input::read_file(const std::string& path, std::string& contents) {
  long long size = -1;
  if (engine_.rank == 0) {
    std::ifstream f(path, std::ios::binary);
    if (f) {
      std::ostringstream ss;
      ss << f.rdbuf();
      contents = ss.str();
      size = static_cast<long long>(contents.size());
    }
  }
  MPI_Bcast(&size, 1, MPI_LONG_LONG, 0, engine_.world);
  if (size < 0) return false;
  contents.resize(static_cast<std::size_t>(size));
  if (size > 0) MPI_Bcast(&contents[0], static_cast<int>(size), MPI_CHAR, 0, engine_.world);
  return true;
}

bool Input::open_source(Source& src, const std::string& path) {
  int ok = 0;
  std::unique_ptr<std::ifstream> f;
  if (engine_.rank == 0) {
    std::error_code ec;
    if (std::filesystem::is_directory(path, ec)) {
      ok = 2;  // opens, reads nothing: the script would end at once without a word
    } else {
      f = std::make_unique<std::ifstream>(path);
      ok = f->is_open() ? 1 : 0;
    }
  }
  MPI_Bcast(&ok, 1, MPI_INT, 0, engine_.world);
  if (ok == 2) throw InputError("'" + path + "' is a directory, not an input script; give a script file");
  if (!ok) return false;
  src.file = std::move(f);
  src.in = src.file.get();
  src.rewindable = true;
  src.name = path;
  src.line = 0;
  return true;
}

bool Input::next_line(Source& src, std::string& text) {
  long long hdr[2] = {0, 0};  // text length + 1 (0: end of input), physical lines
  if (engine_.rank == 0) {
    int lines = 0;
    if (src.in && script::read_command(*src.in, text, lines)) {
      hdr[0] = static_cast<long long>(text.size()) + 1;
      hdr[1] = lines;
    }
  }
  MPI_Bcast(hdr, 2, MPI_LONG_LONG, 0, engine_.world);
  if (hdr[0] == 0) return false;
  text.resize(static_cast<std::size_t>(hdr[0] - 1));
  if (hdr[0] > 1) MPI_Bcast(&text[0], static_cast<int>(hdr[0] - 1), MPI_CHAR, 0, engine_.world);
  src.cmd_line = src.line + 1;
  src.line += static_cast<int>(hdr[1]);
  return true;
}

void Input::echo(const std::string& text) {
  if (!engine_.logger) return;
  if (echo_screen_) engine_.logger->screen_only(text + "\n");
  if (echo_log_) engine_.logger->log_only(text + "\n");
}

void Input::execute(const std::string& line, bool with_echo) {
  if (const auto nul = line.find('\0'); nul != std::string::npos) {
    // everything after it would be cut off or misread without a word
    throw InputError("the line holds a NUL byte at column " + std::to_string(nul + 1) +
                     " (binary data or a damaged script); remove it");
  }
  if (with_echo) echo(line);
  const std::string text = script::strip_comment(line);
  if (text.find_first_not_of(" \t\r\n\v\f") == std::string::npos) return;
  std::string expanded;
  Args words;
  try {
    expanded = variables_->substitute(text);
    if (with_echo && expanded != text) echo(expanded);
    words = script::split_words(expanded);
  } catch (const CommandError&) {
    throw;
  } catch (const InputError& e) {
    throw CommandError(first_word(text), e.what());
  }
  if (words.empty()) return;
  try {
    engine_.execute(words);
  } catch (const CommandError&) {
    throw;
  } catch (const ScriptError&) {
    throw;
  } catch (const InputError& e) {
    throw CommandError(words[0], e.what());
  }
}

void Input::one(const std::string& line) {
  execute(line, true);
}

void Input::run_source() {
  Source& src = *sources_.back();
  auto frames = [this]() {
    std::vector<std::string> f;
    for (const auto& s : sources_)
      f.push_back(s->name + ":" + std::to_string(s->cmd_line));
    return f;
  };
  std::string text;
  while (!quit_ && next_line(src, text)) {
    if (!label_.empty()) {  // after a jump: skip to "label NAME" without executing
      Args w;
      try {
        w = script::split_words(script::strip_comment(text));
      } catch (const InputError&) {
        continue;
      }
      if (w.size() >= 2 && w[0] == "label" && w[1] == label_) label_.clear();
      continue;
    }
    // SIGTERM/SIGUSR1 between commands (e.g. a long set-up or a loop without
    // runs): stop before the next command; the ranks agree first
    if (const int sig = stop_signal_agreed(engine_.world)) {
      throw StopRequested(
          "Stopped by " + signal_name(sig) + " before the command at " + src.name + ":" +
          std::to_string(src.cmd_line) +
          " (no run was in progress: no restart file was written; the files written so far are "
          "complete)");
    }
    {
      Args w;
      try {
        w = script::split_words(script::strip_comment(text));
      } catch (const InputError&) {
      }
      static const char* const kStateless[] = {"label", "jump", "print", "echo", "log"};
      if (!w.empty() && std::find(std::begin(kStateless), std::end(kStateless), w[0]) == std::end(kStateless))
        ++epoch_;
    }
    try {
      execute(text, true);
    } catch (const ScriptError&) {
      throw;
    } catch (const CommandError& e) {
      throw ScriptError(format_error(frames(), e.command, e.what()));
    } catch (const InputError& e) {
      throw ScriptError(format_error(frames(), "", e.what()));
    } catch (const LocatedRunError&) {
      throw;
    } catch (const RunError& e) {  // may be raised on this rank only: add where, nothing collective
      throw LocatedRunError(format_error(frames(), first_word(script::strip_comment(text)), e.what()));
    } catch (const StopRequested&) {
      throw;
    } catch (const std::bad_alloc&) {  // this rank only, like a RunError
      throw LocatedRunError(format_error(
          frames(), first_word(script::strip_comment(text)),
          "out of memory on rank " + std::to_string(engine_.rank) +
              " (the command asked for more memory than this process can get; use fewer particles or more "
              "ranks)"));
    } catch (const std::exception& e) {  // a failure without its own message: say where it happened
      throw LocatedRunError(format_error(frames(), first_word(script::strip_comment(text)),
                                         std::string("internal error: ") + e.what()));
    }
  }
  if (!label_.empty() && !quit_) {
    const std::string missing = label_;
    label_.clear();
    std::vector<std::string> f = frames();
    f.back() = jump_origin_;
    throw ScriptError(format_error(
        f, "jump",
        "label '" + missing + "' not found in " + src.name + "; add 'label " + missing + "' to that file"));
  }
}

namespace {
/// Runs a function when the scope ends (also when an exception leaves it).
class AtExit {
 public:
  explicit AtExit(std::function<void()> f) : f_(std::move(f)) {}
  ~AtExit() { f_(); }
  AtExit(const AtExit&) = delete;
  AtExit& operator=(const AtExit&) = delete;

 private:
  std::function<void()> f_;
};
}  // namespace

void Input::file(const std::string& path) {
  if (sources_.size() >= 64) {
    throw InputError("scripts nested more than 64 deep; does '" + path + "' include itself?");
  }
  auto src = std::make_unique<Source>();
  if (!open_source(*src, path)) {
    throw InputError("cannot open input script '" + path + "'; check the file name and that it is readable");
  }
  sources_.push_back(std::move(src));
  AtExit pop([this] { sources_.pop_back(); });
  run_source();
}

void Input::stream(std::istream& in, const std::string& name) {
  auto src = std::make_unique<Source>();
  src->name = name;
  if (engine_.rank == 0) src->in = &in;
  sources_.push_back(std::move(src));
  AtExit pop([this] { sources_.pop_back(); });
  run_source();
}

void Input::jump(const std::string& file, const std::string& label) {
  if (skip_jump_) {  // a `next` ran out of values: leave the loop
    skip_jump_ = false;
    return;
  }
  if (sources_.empty()) throw InputError("jump works only inside a script file");
  Source& src = *sources_.back();
  const std::string origin = src.name + ":" + std::to_string(src.cmd_line);
  auto seen = jump_epoch_.find(origin);
  if (seen != jump_epoch_.end() && seen->second == epoch_) {
    throw InputError(
        "endless loop: this jump to label '" + label +
        "' is reached again and nothing in between can change the loop (only label, jump, print, "
        "echo or log commands ran); advance a loop variable with 'next' or end the loop with 'if'");
  }
  jump_epoch_[origin] = epoch_;
  if (file == "SELF") {
    int ok = 0;
    if (engine_.rank == 0 && src.in && src.rewindable) {
      src.in->clear();
      src.in->seekg(0);
      ok = src.in->fail() ? 0 : 1;
    }
    MPI_Bcast(&ok, 1, MPI_INT, 0, engine_.world);
    if (!ok) {
      throw InputError("cannot jump back in '" + src.name +
                       "' (standard input or a stream cannot be read again); run the script with -in FILE");
    }
    src.line = 0;
  } else if (!open_source(src, file)) {
    throw InputError("cannot open '" + file + "' to jump to");
  }
  label_ = label;
  jump_origin_ = origin;
}

}  // namespace granary
