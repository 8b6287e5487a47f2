// Every command and style registered in the engine has its page in doc/, and
// doc/README.md lists every page.
#include <catch2/catch.hpp>
#include <filesystem>
#include <fstream>
#include <map>
#include <sstream>
#include <string>

#include "core/registry.h"

namespace fs = std::filesystem;

namespace {

const fs::path kDoc = fs::path(GRANARY_SOURCE_DIR) / "doc";

std::string page_name(std::string style) {
  for (char& c : style)
    if (c == '/') c = '_';
  return style + ".md";
}

std::string read(const fs::path& p) {
  std::ifstream in(p);
  std::stringstream ss;
  ss << in.rdbuf();
  return ss.str();
}

// Commands documented on another command's page.
const std::map<std::string, std::string> kAliases = {
    {"communicate", "comm_modify"},
    {"clog-detect", "clog_detect"},
    {"clog/detect", "clog_detect"},
    {"region-phi", "region_phi"},
    {"region/phi", "region_phi"},
    {"particledistribution/discrete/massbased", "particledistribution/discrete"},
    {"particledistribution/discrete/numberbased", "particledistribution/discrete"},
    {"contact/atom/gran", "contact/atom"},
    {"coord/gran", "contact/atom"},
    {"heat/gran/conduction", "heat/gran"},
    {"hard_particles", "soft_particles"},
    {"lineforce", "planeforce"},
    {"mesh/surface/planar", "mesh/surface"},
    {"rigid", "multisphere"},
    {"multisphere/single", "multisphere"},
    {"bubble", "gran"},
    {"gran_bubble", "gran"},
    {"hybrid/overlay", "hybrid"}};

// The Syntax section of a page (up to the next "## " heading).
std::string syntax_section(const std::string& text) {
  const auto at = text.find("\n## Syntax");
  if (at == std::string::npos) return "";
  const auto end = text.find("\n## ", at + 1);
  return text.substr(at, end == std::string::npos ? std::string::npos : end - at);
}

// Each style's own page: it exists, its title names the style (after `kind`,
// e.g. "fix ") and its Syntax section shows the name the style is registered
// under; a page shared with other spellings (kAliases) names them.
template <class Registry>
void check_pages(const std::string& folder, const std::string& kind) {
  for (const auto& name : Registry::instance().names()) {
    INFO(folder << " style or command '" << name << "'");
    std::string page = name;
    auto alias = kAliases.find(name);
    if (alias != kAliases.end()) page = alias->second;
    const fs::path path = kDoc / folder / page_name(page);
    REQUIRE(fs::exists(path));
    const std::string text = read(path);
    const std::string title = text.substr(0, text.find('\n'));
    INFO("page " << path.filename().string() << ", title '" << title << "'");
    CHECK(title.rfind("# " + kind, 0) == 0);
    const std::string syntax = syntax_section(text);
    CHECK_FALSE(syntax.empty());
    if (alias == kAliases.end()) {
      CHECK(title.find(kind + name) != std::string::npos);
      CHECK(syntax.find(name) != std::string::npos);
    } else {
      CHECK(text.find(name) != std::string::npos);  // another spelling, named on the page
    }
  }
}

}  // namespace

TEST_CASE("every command and style has its own doc page, titled and with its syntax") {
  check_pages<granary::CommandRegistry>("commands", "");
  check_pages<granary::FixRegistry>("fixes", "fix ");
  check_pages<granary::ComputeRegistry>("computes", "compute ");
  check_pages<granary::PairRegistry>("pairs", "pair_style ");
}

TEST_CASE("region and dump styles are described on their command pages") {
  const std::string region = read(kDoc / "commands" / "region.md");
  for (const auto& name : granary::RegionRegistry::instance().names()) {
    INFO("region style " << name);
    CHECK(region.find(name) != std::string::npos);
  }
  const std::string dump = read(kDoc / "commands" / "dump.md");
  for (const auto& name : granary::DumpRegistry::instance().names()) {
    INFO("dump style " << name);
    CHECK(dump.find(name) != std::string::npos);
  }
}

TEST_CASE("doc/README.md lists every page") {
  const std::string index = read(kDoc / "README.md");
  for (const auto& entry : fs::recursive_directory_iterator(kDoc)) {
    if (entry.path().extension() != ".md" || entry.path().filename() == "README.md") continue;
    const std::string rel = fs::relative(entry.path(), kDoc).generic_string();
    if (rel.rfind("images/", 0) == 0) continue;  // generated tables beside the figures, not pages
    INFO("page " << rel);
    CHECK(index.find("(" + rel + ")") != std::string::npos);
  }
}
