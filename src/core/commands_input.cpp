// Commands of the input language: variable, label, jump, next, if, include,
// print, log, echo, clear, quit.
#include <mpi.h>

#include <cstdio>

#include "core/engine.h"
#include "core/error.h"
#include "core/input.h"
#include "core/logger.h"
#include "core/registry.h"
#include "core/variable.h"

namespace granary {
namespace {

void cmd_variable(Engine& e, const Args& a) {
  e.input->variables().set(a);
}

void cmd_label(Engine&, const Args& a) {
  if (a.size() != 1) throw InputError("expected: label ID");
}

void cmd_jump(Engine& e, const Args& a) {
  if (a.empty() || a.size() > 2) throw InputError("expected: jump FILE [LABEL] or jump SELF [LABEL]");
  e.input->jump(a[0], a.size() > 1 ? a[1] : "");
}

void cmd_next(Engine& e, const Args& a) {
  if (e.input->variables().next(a)) e.input->skip_next_jump();
}

void cmd_include(Engine& e, const Args& a) {
  if (a.size() != 1) throw InputError("expected: include FILE");
  e.input->file(a[0]);
}

// if BOOLEAN then CMD... [elif BOOLEAN CMD...]... [else CMD...]
void cmd_if(Engine& e, const Args& a) {
  const std::string usage =
      "expected: if \"BOOLEAN\" then \"COMMAND\" ... [elif \"BOOLEAN\" \"COMMAND\" ...] "
      "[else \"COMMAND\" ...]";
  struct Branch {
    std::string condition;  // empty for else
    Args commands;
  };
  if (a.size() < 2) throw InputError(usage);
  if (a[1] != "then") {
    throw InputError("expected 'then' after the condition '" + a[0] +
                     "'; enclose a condition that contains blanks in quotes");
  }
  std::vector<Branch> branches{{a[0], {}}};
  bool seen_else = false;
  for (std::size_t i = 2; i < a.size(); ++i) {
    if (a[i] == "elif" || a[i] == "else") {
      if (seen_else) throw InputError("'" + a[i] + "' after 'else'; " + usage);
      if (branches.back().commands.empty()) {
        throw InputError("no command before '" + a[i] + "'; " + usage);
      }
      if (a[i] == "else") {
        seen_else = true;
        branches.push_back({"", {}});
      } else {
        if (i + 1 >= a.size()) throw InputError("'elif' needs a condition; " + usage);
        branches.push_back({a[++i], {}});
      }
      continue;
    }
    branches.back().commands.push_back(a[i]);
  }
  if (branches.back().commands.empty()) throw InputError("no command to execute at the end; " + usage);
  for (const auto& b : branches) {
    const bool take = b.condition.empty() || script::evaluate_boolean(e.input->substitute(b.condition));
    if (!take) continue;
    for (const auto& c : b.commands) {
      e.input->one(c);
      if (e.input->quit_requested()) break;
    }
    return;
  }
}

// print TEXT [file F] [append F] [screen yes|no] [universe yes|no]
void cmd_print(Engine& e, const Args& a) {
  if (a.empty()) throw InputError("expected: print TEXT [file FILE] [append FILE] [screen yes/no]");
  const std::string text = e.input->substitute(a[0]);
  std::string path;
  bool append = false, screen = true;
  for (std::size_t i = 1; i < a.size(); i += 2) {
    const std::string& kw = a[i];
    if (kw != "file" && kw != "append" && kw != "screen" && kw != "universe") {
      throw InputError("unknown print keyword '" + kw +
                       "' (expected file, append, screen or universe); enclose text with blanks in quotes");
    }
    if (i + 1 >= a.size()) throw InputError("print keyword '" + kw + "' needs a value");
    if (kw == "file" || kw == "append") {
      path = a[i + 1];
      append = kw == "append";
    } else if (kw == "screen") {
      screen = parse_bool(a[i + 1], "print screen");
    } else {
      parse_bool(a[i + 1], "print universe");  // one partition: same as the screen
    }
  }
  if (screen)
    e.logger->print(text + "\n");
  else
    e.logger->log_only(text + "\n");
  if (!path.empty()) {
    int ok = 1;
    if (e.rank == 0) {
      std::FILE* f = std::fopen(path.c_str(), append ? "a" : "w");
      ok = f ? 1 : 0;
      if (f) {
        std::fputs((text + "\n").c_str(), f);
        std::fclose(f);
      }
    }
    MPI_Bcast(&ok, 1, MPI_INT, 0, e.world);
    if (!ok) throw InputError("cannot write to file '" + path + "'");
  }
}

void cmd_log(Engine& e, const Args& a) {
  if (a.empty() || a.size() > 2 || (a.size() == 2 && a[1] != "append")) {
    throw InputError("expected: log FILE [append] or log none");
  }
  if (a[0] == "none") {
    e.logger->close_log();
    return;
  }
  int ok = 1;
  std::string msg;
  try {
    e.logger->open_log(a[0], a.size() == 2);
  } catch (const InputError& err) {
    ok = 0;
    msg = err.what();
  }
  MPI_Bcast(&ok, 1, MPI_INT, 0, e.world);  // only rank 0 opens the file
  if (!ok) throw InputError(msg.empty() ? "cannot open log file '" + a[0] + "'" : msg);
}

void cmd_echo(Engine& e, const Args& a) {
  if (a.size() != 1) throw InputError("expected: echo none|screen|log|both");
  const std::string& s = a[0];
  if (s == "none")
    e.input->set_echo(false, false);
  else if (s == "screen")
    e.input->set_echo(true, false);
  else if (s == "log")
    e.input->set_echo(false, true);
  else if (s == "both")
    e.input->set_echo(true, true);
  else
    throw InputError("unknown echo style '" + s + "'; expected none, screen, log or both");
}

void cmd_clear(Engine& e, const Args& a) {
  if (!a.empty()) throw InputError("clear takes no arguments");
  e.clear();
}

void cmd_quit(Engine& e, const Args& a) {
  if (a.size() > 1) throw InputError("expected: quit [STATUS]");
  const int status = a.empty() ? 0 : static_cast<int>(parse_int(a[0], "quit status"));
  e.input->request_quit(status);
}

}  // namespace

GRANARY_COMMAND("variable", cmd_variable);
GRANARY_COMMAND("label", cmd_label);
GRANARY_COMMAND("jump", cmd_jump);
GRANARY_COMMAND("next", cmd_next);
GRANARY_COMMAND("include", cmd_include);
GRANARY_COMMAND("if", cmd_if);
GRANARY_COMMAND("print", cmd_print);
GRANARY_COMMAND("log", cmd_log);
GRANARY_COMMAND("echo", cmd_echo);
GRANARY_COMMAND("clear", cmd_clear);
GRANARY_COMMAND("quit", cmd_quit);

}  // namespace granary
