// The script reader: lines, comments, continuation, quotes, $-substitution,
// control flow (label/jump/next/include/if) and dispatch of commands.
//
// Every MPI rank runs the same script: rank 0 reads files and broadcasts each
// command line, so all ranks execute identical commands.
#pragma once

#include <istream>
#include <cstdint>
#include <map>
#include <memory>
#include <string>
#include <vector>

#include "core/utils.h"

namespace granary {

class Engine;
class Variables;

/// Line handling that needs no Engine (used by Input, the tests and the fuzzer).
namespace script {

/// Remove a '#' comment; a '#' inside single, double or triple quotes is kept.
std::string strip_comment(const std::string& line);
/// Split a line into words at blanks. A word that starts with ', " or """ runs
/// to the matching quote, which is removed. Throws InputError on an unclosed
/// quote or a closing quote followed by other characters.
Args split_words(const std::string& line);
/// Number of """ in the text.
int count_triple_quotes(const std::string& text);
/// Read one command from `in`: joins lines ending in '&' (the '&' and the line
/// break are removed) and lines inside an open """ (line breaks kept).
/// Returns false at the end of the input; `lines` = physical lines consumed.
bool read_command(std::istream& in, std::string& command, int& lines);
/// The Boolean of the `if` command (LAMMPS rules): operands are numbers or
/// strings; operators == != < <= > >= && || |^ ! and parentheses. Two strings
/// compare alphabetically; a number never compares with a string. The words
/// yes/on/true and no/off/false count as true and false.
bool evaluate_boolean(const std::string& text);

}  // namespace script

class Input {
 public:
  explicit Input(Engine& engine);
  ~Input();
  Input(const Input&) = delete;
  Input& operator=(const Input&) = delete;

  /// Run a script file to its end (-in and `include`). A file that cannot be
  /// opened raises InputError on every rank.
  void file(const std::string& path);
  /// Run commands from a stream (e.g. stdin; read on rank 0 only).
  void stream(std::istream& in, const std::string& name);
  /// Execute one line (comments, substitution, quotes as in a file), e.g. from
  /// `if` or `run every`.
  void one(const std::string& line);

  Variables& variables();
  /// "in.silo:12 (included from in.main:3)"; empty outside any script.
  std::string location() const;
  bool quit_requested() const { return quit_; }
  /// Exit status given to `quit`.
  int quit_status() const { return quit_status_; }
  void set_echo(bool screen, bool log);

  /// $-substitution of text (print, if and others substitute quoted text when
  /// they execute).
  std::string substitute(const std::string& text);

  // ---- used by the input commands (commands_input.cpp)
  /// `jump FILE|SELF [LABEL]`.
  void jump(const std::string& file, const std::string& label);
  /// `next` exhausted a variable: the next `jump` is skipped.
  void skip_next_jump() { skip_jump_ = true; }
  void request_quit(int status);
  /// Read a whole file on rank 0 and broadcast it (false on every rank if it
  /// cannot be read).
  bool read_file(const std::string& path, std::string& contents);

 private:
  struct Source;
  class EngineLookup;

  void run_source();
  bool next_line(Source& src, std::string& text);
  void execute(const std::string& line, bool echo);
  void echo(const std::string& text);
  bool open_source(Source& src, const std::string& path);

  Engine& engine_;
  std::unique_ptr<Variables> variables_;
  std::unique_ptr<EngineLookup> lookup_;
  std::vector<std::unique_ptr<Source>> sources_;  // innermost last
  bool echo_screen_ = false;
  bool echo_log_ = true;
  bool quit_ = false;
  int quit_status_ = 0;
  bool skip_jump_ = false;
  std::string label_;        // label searched for after a jump ("" = none)
  std::string jump_origin_;  // location of that jump, for "label not found"
  // Endless loops: commands that can change what a loop does next (anything
  // but label, jump, print, echo, log) advance the epoch; a jump reached
  // twice at one epoch loops for ever.
  std::uint64_t epoch_ = 0;
  std::map<std::string, std::uint64_t> jump_epoch_;  // jump location -> epoch at its last pass
};

}  // namespace granary
