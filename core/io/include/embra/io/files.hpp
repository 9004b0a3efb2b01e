// Files named by UTF-8 text, the same on Linux and Windows: every path embra.h takes is UTF-8, which
// Linux uses as it is and Windows must widen to UTF-16 (its char functions read the ANSI code page).
#pragma once

#include <cstdint>
#include <filesystem>
#include <string>
#include <string_view>

namespace embra::io {

/// The path that UTF-8 text names (not std::filesystem::path(std::string): on Windows that reads the
/// ANSI code page).
std::filesystem::path path_from_utf8(const std::string& utf8);
/// A path as UTF-8 text, for messages and for the functions below.
std::string utf8_from_path(const std::filesystem::path& path);

/// The whole content of the regular file at `path`, at most `max_bytes`: opened without blocking
/// and checked before a byte is read, so a folder, device or pipe (/dev/zero, a FIFO; on Windows
/// CON, NUL or a named pipe) is refused rather than read for ever or waited on; a file that grows
/// past max_bytes while read is refused too. On failure returns false with `error` completing a
/// sentence that starts with the path ("could not be opened: ...", "is not a regular file ...", "is
/// larger than N bytes ..."), never quoting the file's content.
bool read_regular_file(const std::string& path, int64_t max_bytes, std::string& out, std::string& error);

/// Writes `text` to `path` through the temporary file `path`.tmp beside it, then renames that over
/// `path`: the file is replaced whole or not at all. On failure returns false with `error` a whole
/// sentence ("cannot write P.tmp: ...", "cannot replace P: ...") and leaves no temporary file.
bool replace_file(const std::string& path, std::string_view text, std::string& error);

/// The folder of the file `path` names, as text a path can be joined to: "." for a bare name, "/"
/// for a file at the root; on Windows "\" separates as "/" does and "C:\" is a root.
std::string folder_of(const std::string& path);

}  // namespace embra::io
