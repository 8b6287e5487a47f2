// Small helpers shared by the VTK dump styles: file-name handling, XML text,
// and the ParaView .pvd collection that lists every frame with its simulated
// time (rewritten as a whole after each frame, see core/atomic_file.h, so it
// is always complete).
#pragma once

#include <cerrno>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <string>
#include <vector>

#include "core/atomic_file.h"
#include "core/error.h"
#include "core/utils.h"

namespace granary {
namespace vtkio {

/// ".vtp" for "dir/a_*.vtp"; "" when the last path component has no dot.
inline std::string extension(const std::string& file) {
  const auto slash = file.find_last_of('/');
  const auto dot = file.find_last_of('.');
  if (dot == std::string::npos || (slash != std::string::npos && dot < slash)) return "";
  return file.substr(dot);
}

inline std::string strip_extension(const std::string& file) {
  return file.substr(0, file.size() - extension(file).size());
}

inline std::string xml_escape(const std::string& text) {
  std::string out;
  for (char ch : text) {
    switch (ch) {
      case '&':
        out += "&amp;";
        break;
      case '<':
        out += "&lt;";
        break;
      case '>':
        out += "&gt;";
        break;
      case '"':
        out += "&quot;";
        break;
      default:
        out += ch;
    }
  }
  return out;
}

inline const char* byte_order() {
  const std::uint16_t word = 1;
  return *reinterpret_cast<const unsigned char*>(&word) == 1 ? "LittleEndian" : "BigEndian";
}

/// Shortest decimal text (15..17 significant digits) that reads back as `value`.
inline std::string exact_text(double value) {
  char buf[64];
  for (int digits = 15; digits <= 17; ++digits) {
    std::snprintf(buf, sizeof buf, "%.*g", digits, value);
    if (std::strtod(buf, nullptr) == value) break;
  }
  return buf;
}

/// The .pvd name of a dump file pattern: '*' removed, extension replaced by
/// .pvd; `fallback` names the file when nothing of the pattern's name is left.
inline std::string pvd_name(const std::string& pattern, const std::string& fallback) {
  namespace fs = std::filesystem;
  std::string stem = strip_extension(pattern);
  const auto star = stem.find('*');
  if (star != std::string::npos) stem.erase(star, 1);
  if (fs::path(stem).filename().empty()) stem = (fs::path(stem).parent_path() / fallback).string();
  return stem + ".pvd";
}

/// Settings of a VTK XML writer (vtkXML*Writer): 64-bit headers; binary data
/// compressed with `compressor` (zlib, lz4, lzma, none), base64-encoded inside
/// each DataArray element ("binary" format), or ASCII. Not the appended
/// format: the XML readers of VTK 9.1 and 9.2 (Debian 12's VTK and ParaView
/// 5.11) cannot read appended data, raw or encoded, with the expat of Debian
/// 12's security updates (2.5.0-1+deb12u2 and later: reparse deferral), which
/// makes them stop at the appended-data section with a parse error.
template <class Writer>
void configure_writer(Writer* w, bool binary, const std::string& compressor) {
  w->SetHeaderTypeToUInt64();
  if (!binary) {
    w->SetDataModeToAscii();
    w->SetCompressorTypeToNone();
    return;
  }
  w->SetDataModeToBinary();
  if (compressor == "none")
    w->SetCompressorTypeToNone();
  else if (compressor == "lz4")
    w->SetCompressorTypeToLZ4();
  else if (compressor == "lzma")
    w->SetCompressorTypeToLZMA();
  else
    w->SetCompressorTypeToZLib();
}

/// How frames are written, set by dump_modify binary / compression / pad.
struct WriteOptions {
  bool binary = true;
  std::string compressor = "zlib";
  int pad = 0;  // zero-padding of the step in file names

  /// Parse one of those keywords at args[k]; returns the words used (0: not one of them).
  int parse(const Args& args, std::size_t k, const std::string& where) {
    const std::string& key = args[k];
    if (k + 1 >= args.size()) return 0;
    const std::string& v = args[k + 1];
    if (key == "binary") {
      binary = parse_bool(v, where);
      return 2;
    }
    if (key == "compression") {
      if (v != "zlib" && v != "none" && v != "lz4" && v != "lzma") {
        throw InputError(where + ": expected zlib, lz4, lzma or none, got '" + v + "'");
      }
      compressor = v;
      return 2;
    }
    if (key == "pad") {
      const long long n = parse_int(v, where);
      if (n < 0 || n > 30) throw InputError(where + ": pad must be 0..30");
      pad = static_cast<int>(n);
      return 2;
    }
    return 0;
  }
};

/// A ParaView collection file (one rank writes it).
class PvdCollection {
 public:
  /// The collection file; empty = none.
  std::string path;

  /// Forget the frames listed so far (e.g. when the path changes).
  void clear() { entries_.clear(); }

  /// List `frame` at simulated `time` (a frame already listed moves to the
  /// end with the new time) and rewrite the file (a temporary file, renamed).
  /// Returns "" or an error message.
  std::string add(const std::string& frame, double time) {
    namespace fs = std::filesystem;
    // paths in a .pvd are relative to the .pvd's own directory
    const fs::path dir = fs::absolute(fs::path(path)).lexically_normal().parent_path();
    const std::string rel =
        fs::absolute(fs::path(frame)).lexically_normal().lexically_relative(dir).generic_string();
    for (auto it = entries_.begin(); it != entries_.end();)
      it = it->file == rel ? entries_.erase(it) : it + 1;
    entries_.push_back({time, rel});

    std::string text = "<?xml version=\"1.0\"?>\n<VTKFile type=\"Collection\" version=\"0.1\" byte_order=\"";
    text += byte_order();
    text += "\">\n  <Collection>\n";
    for (const auto& e : entries_) {
      text += "    <DataSet timestep=\"" + exact_text(e.time) + "\" group=\"\" part=\"0\" file=\"" +
              xml_escape(e.file) + "\"/>\n";
    }
    text += "  </Collection>\n</VTKFile>\n";

    return replace_file(path, text);
  }

 private:
  struct Entry {
    double time;
    std::string file;
  };
  std::vector<Entry> entries_;
};

}  // namespace vtkio
}  // namespace granary
