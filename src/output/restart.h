// Restart files: `write_restart FILE`, `restart N FILE [FILE2]`, `read_restart FILE`.
//
// Binary, versioned and self-describing: a header (magic, format version,
// byte-order mark), a table of named sections with their sizes and CRC-32
// checksums, then the sections. Rank 0 writes to a temporary file and renames
// it (core/atomic_file.h), so a crash never leaves a half-written restart. A file written on N ranks reads
// on any number of ranks. See doc/restart_format.md.
#pragma once

#include <cstdint>
#include <string>

namespace granary {

class Engine;

/// Write the complete state (collective).
void write_restart(Engine& engine, const std::string& file);
/// Read a restart into an engine that has no box yet (collective).
void read_restart(Engine& engine, const std::string& file);
/// Replace a '*' in a file name by the step number.
std::string expand_step(const std::string& file, std::int64_t step);

}  // namespace granary
