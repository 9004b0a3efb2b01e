// Files named by UTF-8 text (files.hpp): POSIX calls on Linux, the wide-character Win32 calls on
// Windows.
#include "embra/io/files.hpp"

#include <algorithm>
#include <cerrno>
#include <cstdio>
#include <cstring>

#ifdef _WIN32
#ifndef WIN32_LEAN_AND_MEAN
#define WIN32_LEAN_AND_MEAN
#endif
#ifndef NOMINMAX
#define NOMINMAX
#endif
#include <windows.h>
#else
#include <fcntl.h>
#include <sys/stat.h>
#include <unistd.h>
#endif

namespace embra::io {

namespace {

#ifdef _WIN32
const char* const kInvalidUtf8 = "is not valid UTF-8 (a path is UTF-8 text)";

/// UTF-8 to UTF-16; false on bytes that are not UTF-8.
bool widen(const std::string& utf8, std::wstring& out) {
  out.clear();
  if (utf8.empty()) return true;
  if (utf8.size() > static_cast<size_t>(INT32_MAX)) return false;
  const int n = static_cast<int>(utf8.size());
  const int wide = MultiByteToWideChar(CP_UTF8, MB_ERR_INVALID_CHARS, utf8.data(), n, nullptr, 0);
  if (wide <= 0) return false;
  out.resize(static_cast<size_t>(wide));
  return MultiByteToWideChar(CP_UTF8, MB_ERR_INVALID_CHARS, utf8.data(), n, out.data(), wide) == wide;
}

/// What Windows says of an error code, as one line.
std::string win32_message(DWORD code) {
  char* text = nullptr;
  const DWORD n = FormatMessageA(
      FORMAT_MESSAGE_ALLOCATE_BUFFER | FORMAT_MESSAGE_FROM_SYSTEM | FORMAT_MESSAGE_IGNORE_INSERTS, nullptr, code,
      MAKELANGID(LANG_NEUTRAL, SUBLANG_DEFAULT), reinterpret_cast<char*>(&text), 0, nullptr);
  std::string s = n > 0 && text != nullptr ? std::string(text, n) : "Windows error " + std::to_string(code);
  if (text != nullptr) LocalFree(text);
  while (!s.empty() && (s.back() == '\n' || s.back() == '\r' || s.back() == ' ' || s.back() == '.')) s.pop_back();
  return s;
}
#endif

}  // namespace

std::filesystem::path path_from_utf8(const std::string& utf8) {
#ifdef _WIN32
  return std::filesystem::path(std::u8string(utf8.begin(), utf8.end()));
#else
  return std::filesystem::path(utf8);  // a Linux name is bytes; UTF-8 is what hosts pass
#endif
}

std::string utf8_from_path(const std::filesystem::path& path) {
#ifdef _WIN32
  const std::u8string u8 = path.u8string();
  return std::string(u8.begin(), u8.end());
#else
  return path.string();
#endif
}

bool read_regular_file(const std::string& path, int64_t max_bytes, std::string& out, std::string& error) {
  const auto refuse = [&](std::string why) {
    error = std::move(why);
    return false;
  };
  const std::string too_large = "is larger than " + std::to_string(max_bytes) + " bytes, the most it may have";
#ifdef _WIN32
  std::wstring wide;
  if (!widen(path, wide)) return refuse(kInvalidUtf8);
  // FILE_FLAG_BACKUP_SEMANTICS opens a folder too, so that it is refused below as what it is.
  const HANDLE h = CreateFileW(wide.c_str(), GENERIC_READ, FILE_SHARE_READ | FILE_SHARE_WRITE | FILE_SHARE_DELETE,
                               nullptr, OPEN_EXISTING, FILE_FLAG_BACKUP_SEMANTICS, nullptr);
  if (h == INVALID_HANDLE_VALUE) return refuse("could not be opened: " + win32_message(GetLastError()));
  struct Closer {
    HANDLE h;
    ~Closer() { CloseHandle(h); }
  } closer{h};
  BY_HANDLE_FILE_INFORMATION info;
  // A console, NUL or a pipe is not FILE_TYPE_DISK; reading one could wait for ever.
  if (GetFileType(h) != FILE_TYPE_DISK) return refuse("is not a regular file (a folder, device or pipe is refused)");
  if (!GetFileInformationByHandle(h, &info)) return refuse("could not be read: " + win32_message(GetLastError()));
  if (info.dwFileAttributes & FILE_ATTRIBUTE_DIRECTORY)
    return refuse("is not a regular file (a folder, device or pipe is refused)");
  const uint64_t size = (static_cast<uint64_t>(info.nFileSizeHigh) << 32) | info.nFileSizeLow;
  if (size > static_cast<uint64_t>(max_bytes)) return refuse(too_large);
#else
  const int fd = ::open(path.c_str(), O_RDONLY | O_NONBLOCK | O_NOCTTY | O_CLOEXEC);
  if (fd < 0) return refuse(std::string("could not be opened: ") + std::strerror(errno));
  struct Closer {
    int fd;
    ~Closer() { ::close(fd); }
  } closer{fd};
  struct stat st;
  if (::fstat(fd, &st) != 0) return refuse(std::string("could not be read: ") + std::strerror(errno));
  if (!S_ISREG(st.st_mode)) return refuse("is not a regular file (a folder, device or pipe is refused)");
  if (st.st_size > max_bytes) return refuse(too_large);
  const auto size = static_cast<uint64_t>(st.st_size);
#endif
  const size_t cap = static_cast<size_t>(max_bytes) + 1;  // one byte more shows a file that grew
  std::string text;
  text.resize(static_cast<size_t>(std::min<uint64_t>(size + 1, cap)));
  size_t got = 0;
  for (;;) {
    if (got == text.size()) {
      if (text.size() >= cap) return refuse(too_large);
      text.resize(std::min(2 * text.size(), cap));
    }
#ifdef _WIN32
    DWORD n = 0;
    const auto want = static_cast<DWORD>(std::min<size_t>(text.size() - got, size_t{1} << 30));
    if (!ReadFile(h, text.data() + got, want, &n, nullptr))
      return refuse("could not be read: " + win32_message(GetLastError()));
#else
    const ssize_t n = ::read(fd, text.data() + got, text.size() - got);
    if (n < 0 && errno == EINTR) continue;
    if (n < 0) return refuse(std::string("could not be read: ") + std::strerror(errno));
#endif
    if (n == 0) break;
    got += static_cast<size_t>(n);
  }
  text.resize(got);
  out = std::move(text);
  return true;
}

bool replace_file(const std::string& path, std::string_view text, std::string& error) {
  const std::string tmp = path + ".tmp";
#ifdef _WIN32
  std::wstring wide_path, wide_tmp;
  if (!widen(path, wide_path) || !widen(tmp, wide_tmp)) {
    error = "cannot write " + tmp + ": the path " + kInvalidUtf8;
    return false;
  }
  std::FILE* f = _wfopen(wide_tmp.c_str(), L"wb");
#else
  std::FILE* f = std::fopen(tmp.c_str(), "wb");
#endif
  if (f == nullptr) {
    error = "cannot write " + tmp + ": " + std::strerror(errno);
    return false;
  }
  const bool ok = std::fwrite(text.data(), 1, text.size(), f) == text.size();
#ifdef _WIN32
  const auto remove_tmp = [&] { _wremove(wide_tmp.c_str()); };
#else
  const auto remove_tmp = [&] { std::remove(tmp.c_str()); };
#endif
  if (std::fclose(f) != 0 || !ok) {
    remove_tmp();
    error = "cannot write " + tmp;
    return false;
  }
#ifdef _WIN32
  // rename() on Windows refuses an existing target; MoveFileEx replaces it.
  if (!MoveFileExW(wide_tmp.c_str(), wide_path.c_str(), MOVEFILE_REPLACE_EXISTING | MOVEFILE_WRITE_THROUGH)) {
    const DWORD code = GetLastError();
    remove_tmp();
    error = "cannot replace " + path + ": " + win32_message(code);
    return false;
  }
#else
  if (std::rename(tmp.c_str(), path.c_str()) != 0) {
    const int code = errno;
    remove_tmp();
    error = "cannot replace " + path + ": " + std::strerror(code);
    return false;
  }
#endif
  return true;
}

std::string folder_of(const std::string& path) {
#ifdef _WIN32
  const auto slash = path.find_last_of("/\\");
  // "C:\scene.json" is at the root of C:, "C:scene.json" in C:'s current folder.
  const bool drive = path.size() >= 2 && path[1] == ':';
  if (slash == std::string::npos) return drive ? path.substr(0, 2) : ".";
  if (slash == 0 || (drive && slash == 2)) return path.substr(0, slash + 1);
  return path.substr(0, slash);
#else
  const auto slash = path.find_last_of('/');
  return slash == std::string::npos ? "." : slash == 0 ? "/" : path.substr(0, slash);
#endif
}

}  // namespace embra::io
