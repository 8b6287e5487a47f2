// Files replaced as a whole (restart files, VTK frames and their index and
// .pvd files, rewritten logs): the new content goes to a temporary file in the
// same directory, which is then renamed over the final name. A reader, or a
// run killed in the middle of the write, never finds a partial file under the
// final name: it holds the old content or the new one.
//
// The temporary name is unique (".NAME.tmp-PID-N", created exclusively, so an
// existing file or directory of that name is never used), and on failure only
// the regular file this code created is removed.
#pragma once

#include <cstdio>
#include <functional>
#include <string>

namespace granary {

/// Write `path` through `write`, which receives the temporary file's stream
/// (its errors are checked after it returns). Returns "" or a message
/// "cannot write 'PATH': reason".
std::string replace_file(const std::string& path, const std::function<void(std::FILE*)>& write);

/// For writers that open a file by name (VTK): `write` gets the temporary
/// file's name (an empty file) and returns "" or its own error message.
std::string replace_file_by_name(const std::string& path,
                                 const std::function<std::string(const std::string& temp)>& write);

/// Write `text` to `path` as a whole.
std::string replace_file(const std::string& path, const std::string& text);

/// The prefix of the temporary names used for `path` (".NAME.tmp-"), for tools
/// and tests that look for leftovers.
std::string temp_prefix(const std::string& path);

}  // namespace granary
