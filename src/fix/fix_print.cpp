// fix ID group print N STRING [file F | append F] [screen yes|no] [title T|none]
//
// Every N steps (at the end of steps that are multiples of N) substitutes the
// variables in STRING ($x, ${name}, $(formula)) and writes it as one line to
// the screen and log file (unless screen no) and to the file, which `file`
// overwrites and `append` appends to; the file starts with the title line
// ("# Fix print output for fix ID" unless given; none: no title). Variables
// are evaluated on every rank (they may need sums over ranks); rank 0 writes.
#include <cstdio>

#include "core/engine.h"
#include "core/error.h"
#include "core/input.h"
#include "core/logger.h"
#include "core/registry.h"
#include "core/variable.h"
#include "fix/fix.h"

namespace granary {

namespace {

const char* kUsage =
    "fix ID group print N \"text with $variables\" [file FILE | append FILE] [screen yes|no] [title "
    "TEXT|none]";

class FixPrint : public Fix {
 public:
  FixPrint(Engine& engine, const Args& args) : Fix(engine, args) {
    if (args.size() < 5) throw InputError(std::string("wrong number of arguments; usage: ") + kUsage);
    const long long n = parse_int(args[3], "the period N of fix print");
    if (n <= 0) throw InputError("fix print: N must be positive (got " + args[3] + ")");
    nevery = static_cast<int>(n);
    text_ = args[4];
    std::string file, title = "# Fix print output for fix " + id;
    bool append = false;
    for (std::size_t k = 5; k < args.size(); k += 2) {
      const std::string& key = args[k];
      if (key != "file" && key != "append" && key != "screen" && key != "title") {
        const std::string hint = did_you_mean(key, {"file", "append", "screen", "title"});
        throw InputError("unknown fix print keyword '" + key + "'" + (hint.empty() ? "" : "; " + hint) +
                         "; usage: " + kUsage);
      }
      if (k + 1 >= args.size())
        throw InputError("fix print keyword '" + key + "' needs a value; usage: " + kUsage);
      const std::string& val = args[k + 1];
      if (key == "file" || key == "append") {
        if (!file.empty()) throw InputError("fix print: give one of file and append, once");
        file = val;
        append = key == "append";
      } else if (key == "screen") {
        screen_ = parse_bool(val, "fix print screen");
      } else {
        title = val;
      }
    }
    if (!file.empty() && engine.rank == 0) {
      fp_ = std::fopen(file.c_str(), append ? "a" : "w");
      if (!fp_)
        throw InputError("fix print cannot open file '" + file + "' for " +
                         (append ? "appending" : "writing") +
                         "; check that its folder exists and is writable");
      if (title != "none") {
        std::fprintf(fp_, "%s\n", title.c_str());
        std::fflush(fp_);
      }
    }
  }

  ~FixPrint() override {
    if (fp_) std::fclose(fp_);
  }

  unsigned hooks() const override { return END_OF_STEP; }

  /// Every $x and ${name} of the text names a variable that exists (formulas
  /// $(...) are checked when they are evaluated).
  void init() override {
    const Variables& vars = engine_.input->variables();
    for (std::size_t at = text_.find('$'); at != std::string::npos; at = text_.find('$', at + 1)) {
      if (at + 1 >= text_.size() || text_[at + 1] == '(') continue;
      std::string name(1, text_[at + 1]);
      if (text_[at + 1] == '{') {
        const auto close = text_.find('}', at);
        if (close == std::string::npos)
          throw InputError("fix print " + id + ": unclosed ${ in \"" + text_ + "\"");
        name = text_.substr(at + 2, close - at - 2);
      }
      if (!vars.find(name))
        throw InputError("fix print " + id + ": the text \"" + text_ + "\" uses variable '" + name +
                         "', which does not exist; define it with the variable command");
    }
  }

  void end_of_step() override {
    const std::string line = engine_.input->variables().substitute(text_) + "\n";
    if (screen_) engine_.logger->print(line);
    if (fp_) {
      std::fputs(line.c_str(), fp_);
      std::fflush(fp_);
    }
  }

 private:
  std::string text_;
  bool screen_ = true;
  std::FILE* fp_ = nullptr;
};

}  // namespace

GRANARY_FIX_STYLE("print", FixPrint);

}  // namespace granary
