// STL files for the mesh-wall tests: triangle soups built from rectangles,
// written as ASCII or binary STL into a temporary directory.
#pragma once

#include <array>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <fstream>
#include <string>
#include <vector>

#include "core/vec3.h"
#include "script_engine.h"

namespace mesh_files {

using granary::Vec3;
using Triangle = std::array<Vec3, 3>;

/// The rectangle o + s u + t v (s, t in [0, 1]) cut into nu x nv cells of two
/// triangles each; the diagonal alternates from cell to cell.
inline void add_rectangle(std::vector<Triangle>& tris, const Vec3& o, const Vec3& u, const Vec3& v, int nu,
                          int nv) {
  for (int i = 0; i < nu; ++i)
    for (int j = 0; j < nv; ++j) {
      const Vec3 p00 = o + (double(i) / nu) * u + (double(j) / nv) * v;
      const Vec3 p10 = o + (double(i + 1) / nu) * u + (double(j) / nv) * v;
      const Vec3 p01 = o + (double(i) / nu) * u + (double(j + 1) / nv) * v;
      const Vec3 p11 = o + (double(i + 1) / nu) * u + (double(j + 1) / nv) * v;
      if ((i + j) % 2 == 0) {
        tris.push_back({p00, p10, p11});
        tris.push_back({p00, p11, p01});
      } else {
        tris.push_back({p00, p10, p01});
        tris.push_back({p10, p11, p01});
      }
    }
}

inline void write_ascii(const std::string& file, const std::vector<Triangle>& tris) {
  std::FILE* fp = std::fopen(file.c_str(), "w");
  std::fprintf(fp, "solid test\n");
  for (const auto& t : tris) {
    const Vec3 n = (t[1] - t[0]).cross(t[2] - t[0]).normalized();
    std::fprintf(fp, "  facet normal %.17g %.17g %.17g\n    outer loop\n", n[0], n[1], n[2]);
    for (const auto& p : t)
      std::fprintf(fp, "      vertex %.17g %.17g %.17g\n", p[0], p[1], p[2]);
    std::fprintf(fp, "    endloop\n  endfacet\n");
  }
  std::fprintf(fp, "endsolid test\n");
  std::fclose(fp);
}

/// Binary STL (float32 coordinates): use values that floats hold exactly.
inline void write_binary(const std::string& file, const std::vector<Triangle>& tris) {
  std::ofstream out(file, std::ios::binary);
  char header[80] = {};
  out.write(header, 80);
  const std::uint32_t n = static_cast<std::uint32_t>(tris.size());
  out.write(reinterpret_cast<const char*>(&n), 4);
  for (const auto& t : tris) {
    const Vec3 nn = (t[1] - t[0]).cross(t[2] - t[0]).normalized();
    float v[12];
    for (int d = 0; d < 3; ++d)
      v[d] = static_cast<float>(nn[d]);
    for (int c = 0; c < 3; ++c)
      for (int d = 0; d < 3; ++d)
        v[3 + 3 * c + d] = static_cast<float>(t[c][d]);
    out.write(reinterpret_cast<const char*>(v), sizeof v);
    const std::uint16_t attr = 0;
    out.write(reinterpret_cast<const char*>(&attr), 2);
  }
}

/// A fresh temporary directory (removed by the caller if wanted).
inline std::string temp_dir() {
  std::vector<char> t = granary::test::temp_template("granary_mesh_");
  const char* d = mkdtemp(t.data());
  return d ? std::string(d) : std::string(".");
}

}  // namespace mesh_files
