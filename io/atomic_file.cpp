#include "atomic_file.h"

#include <fcntl.h>
#include <sys/stat.h>
#include <unistd.h>

#include <atomic>
#include <cerrno>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <stdexcept>

namespace gi::io {

namespace fs = std::filesystem;

namespace {

// A new empty file beside `target`, hidden and unique to this process:
// ".NAME.gi-PID-N.tmp" (NAME cut to 64 bytes, so that long names still fit).
// Returns its path, or "" with errno set.
std::string createTemporary(const fs::path& target) {
  static std::atomic<unsigned> counter{0};
  const std::string name = target.filename().string().substr(0, 64);
  for (int attempt = 0; attempt < 1000; ++attempt) {
    const fs::path tmp = target.parent_path() /
                         ("." + name + ".gi-" + std::to_string(::getpid()) + "-" + std::to_string(counter++) + ".tmp");
    const int fd = ::open(tmp.c_str(), O_WRONLY | O_CREAT | O_EXCL | O_CLOEXEC, 0666);
    if (fd >= 0) {
      ::close(fd);
      return tmp.string();
    }
    if (errno != EEXIST) return "";
  }
  return "";
}

// Flushes the file's data to the device, so that the rename never publishes
// a file whose blocks a crash would lose.
bool syncFile(const std::string& path) {
  const int fd = ::open(path.c_str(), O_RDONLY | O_CLOEXEC);
  if (fd < 0) return false;
  const bool ok = ::fsync(fd) == 0;
  return ::close(fd) == 0 && ok;
}

std::string replaceAll(std::string s, const std::string& from, const std::string& to) {
  if (from.empty()) return s;
  for (size_t k = s.find(from); k != std::string::npos; k = s.find(from, k + to.size())) s.replace(k, from.size(), to);
  return s;
}

}  // namespace

std::string linkTarget(const std::string& path) {
  fs::path p(path);
  std::error_code ec;
  for (int hops = 0; hops < 40 && fs::is_symlink(fs::symlink_status(p, ec)); ++hops) {
    const fs::path t = fs::read_symlink(p, ec);
    if (ec) break;
    p = t.is_absolute() ? t : p.parent_path() / t;
  }
  return p.string();
}

void writeAtomically(const std::string& path, const std::function<void(const std::string& temp)>& write) {
  const std::string target = linkTarget(path);
  struct stat st {};
  const bool exists = ::stat(target.c_str(), &st) == 0;
  if (exists && !S_ISREG(st.st_mode)) {  // a device or a pipe: no file to replace
    write(path);
    return;
  }
  const std::string tmp = createTemporary(fs::path(target));
  if (tmp.empty()) throw std::runtime_error("cannot write " + path + ": " + std::strerror(errno));
  try {
    if (exists) ::chmod(tmp.c_str(), st.st_mode & 07777);  // the permissions of the file it replaces
    write(tmp);
    if (!syncFile(tmp)) throw std::runtime_error("cannot write " + path + ": " + std::strerror(errno));
    if (std::rename(tmp.c_str(), target.c_str()) != 0)
      throw std::runtime_error("cannot write " + path + ": " + std::strerror(errno));
  } catch (const std::exception& e) {
    ::unlink(tmp.c_str());
    throw std::runtime_error(replaceAll(e.what(), tmp, path));
  } catch (...) {
    ::unlink(tmp.c_str());
    throw;
  }
}

void writeFileAtomically(const std::string& path, std::string_view bytes) {
  writeAtomically(path, [&](const std::string& temp) {
    std::ofstream f(temp, std::ios::binary | std::ios::trunc);
    f.write(bytes.data(), std::streamsize(bytes.size()));
    f.close();
    if (!f) throw std::runtime_error("cannot write " + temp + ": " + std::strerror(errno));
  });
}

std::string cannotCreateBeside(const std::string& path) {
  const std::string tmp = createTemporary(fs::path(linkTarget(path)));
  if (tmp.empty()) return std::strerror(errno);
  ::unlink(tmp.c_str());
  return "";
}

}  // namespace gi::io
