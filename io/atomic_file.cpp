#include "atomic_file.h"

#include <fcntl.h>
#include <signal.h>
#include <sys/stat.h>
#include <unistd.h>

#include <atomic>
#include <cerrno>
#include <chrono>
#include <cstdlib>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <mutex>
#include <optional>
#include <set>
#include <stdexcept>
#include <vector>

namespace gi::io {

namespace fs = std::filesystem;

namespace {

// How old a temporary of a process that no longer runs must be before a
// later write of the same file removes it: a write of another machine's
// process into a shared folder (its PID means nothing here) is long over.
constexpr auto kStaleAfter = std::chrono::minutes(10);

// Removes the temporaries a process killed outright (SIGKILL, the kernel's
// out-of-memory killer, a power cut) left in the folder `target` is written
// to: ".NAME.gi-PID-N.tmp" whose PID runs no process here and that were
// last written more than kStaleAfter ago. Each folder once per process (a
// batch writing thousands of files into one folder reads it once). The
// signals a run can catch remove their own (removeTemporariesAndStop).
void removeStaleTemporaries(const fs::path& target) {
  static std::mutex m;
  static std::set<std::string> done;
  const fs::path dir = target.parent_path().empty() ? fs::path(".") : target.parent_path();
  {
    std::lock_guard<std::mutex> lock(m);
    if (!done.insert(dir.string()).second) return;
  }
  std::error_code ec;
  const auto now = fs::file_time_type::clock::now();
  for (fs::directory_iterator it(dir, ec), end; !ec && it != end; it.increment(ec)) {
    const std::string f = it->path().filename().string();
    const size_t mark = f.rfind(".gi-");
    if (f.size() < 10 || f[0] != '.' || mark == std::string::npos || mark < 2 || f.compare(f.size() - 4, 4, ".tmp") != 0)
      continue;
    const std::string tail = f.substr(mark + 4, f.size() - 4 - mark - 4);  // "PID-N"
    const size_t dash = tail.find('-');
    if (dash == 0 || dash == std::string::npos || dash + 1 == tail.size() || tail.find('-', dash + 1) != std::string::npos ||
        tail.find_first_not_of("0123456789-") != std::string::npos)
      continue;
    const long pid = std::strtol(tail.substr(0, dash).c_str(), nullptr, 10);
    if (pid <= 0 || pid == long(::getpid()) || !(::kill(pid_t(pid), 0) == -1 && errno == ESRCH)) continue;
    std::error_code tec;
    const auto written = fs::last_write_time(it->path(), tec);
    if (tec || now - written < kStaleAfter || !it->is_regular_file(tec)) continue;
    fs::remove(it->path(), tec);
  }
}

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

// The temporaries being written, for the signal handler: fixed slots whose
// paths it reads without allocating (unlink is async-signal-safe).
constexpr int kSlots = 32;
constexpr size_t kPathBytes = 4096;
struct Slot {
  std::atomic<bool> claimed{false}, ready{false};  // taken by a writer; its path complete
  char path[kPathBytes];
};
Slot g_slots[kSlots];

// Claims a slot for `tmp` (none free or too long a path: not listed).
int listTemporary(const std::string& tmp) {
  if (tmp.size() >= kPathBytes) return -1;
  for (int k = 0; k < kSlots; ++k) {
    bool expected = false;
    Slot& s = g_slots[k];
    if (!s.claimed.compare_exchange_strong(expected, true)) continue;
    std::memcpy(s.path, tmp.c_str(), tmp.size() + 1);
    s.ready.store(true);
    return k;
  }
  return -1;
}
void unlistTemporary(int k) {
  if (k < 0) return;
  g_slots[k].ready.store(false);
  g_slots[k].claimed.store(false);
}

extern "C" void removeTemporariesAndStop(int sig) {
  for (Slot& s : g_slots)
    if (s.ready.load()) ::unlink(s.path);
  ::signal(sig, SIG_DFL);
  ::raise(sig);
}

// The open transaction's held-back files, in the order written.
struct Pending {
  std::string tmp, target, path;
  int slot;
};
std::optional<std::vector<Pending>> g_pending;  // engaged while a transaction is open

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
    // A pipe no process reads would block the write's open for ever (an
    // outside audit: `gi ao in.ply -o fifo.ply` hung): its open without
    // waiting fails then, and is said. One that a process reads is written
    // to, the probe held open until the write is done (closing it first
    // would end the reader's input).
    int probe = -1;
    if (S_ISFIFO(st.st_mode)) {
      probe = ::open(target.c_str(), O_WRONLY | O_NONBLOCK | O_CLOEXEC);
      if (probe < 0)
        throw std::runtime_error("cannot write " + path + ": " +
                                 (errno == ENXIO ? std::string("it is a pipe that no process reads") : std::strerror(errno)));
    }
    struct Probe {
      int fd;
      ~Probe() {
        if (fd >= 0) ::close(fd);
      }
    } held{probe};
    write(path);
    return;
  }
  removeStaleTemporaries(fs::path(target));
  const std::string tmp = createTemporary(fs::path(target));
  if (tmp.empty()) throw std::runtime_error("cannot write " + path + ": " + std::strerror(errno));
  struct Listed {
    int slot;
    ~Listed() { unlistTemporary(slot); }
  } listed{listTemporary(tmp)};
  try {
    if (exists) ::chmod(tmp.c_str(), st.st_mode & 07777);  // the permissions of the file it replaces
    write(tmp);
    if (!syncFile(tmp)) throw std::runtime_error("cannot write " + path + ": " + std::strerror(errno));
    if (g_pending) {  // held back until the transaction commits (still removed on a signal)
      g_pending->push_back({tmp, target, path, listed.slot});
      listed.slot = -1;
      return;
    }
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

OutputTransaction::OutputTransaction() {
  if (g_pending) throw std::logic_error("an output transaction is already open");
  g_pending.emplace();
}

OutputTransaction::~OutputTransaction() {
  if (!g_pending) return;  // committed
  for (const Pending& p : *g_pending) {
    ::unlink(p.tmp.c_str());
    unlistTemporary(p.slot);
  }
  g_pending.reset();
}

void OutputTransaction::commit() {
  if (!g_pending) throw std::logic_error("no output transaction is open");
  std::vector<Pending> files = std::move(*g_pending);
  g_pending.reset();
  for (size_t k = 0; k < files.size(); ++k) {
    if (std::rename(files[k].tmp.c_str(), files[k].target.c_str()) != 0) {
      const std::string why = std::strerror(errno);
      for (size_t j = k; j < files.size(); ++j) ::unlink(files[j].tmp.c_str()), unlistTemporary(files[j].slot);
      throw std::runtime_error("cannot write " + files[k].path + ": " + why);
    }
    unlistTemporary(files[k].slot);
  }
}

void removeTemporariesOnSignals() {
  struct sigaction sa {};
  sa.sa_handler = removeTemporariesAndStop;
  sigemptyset(&sa.sa_mask);
  for (int sig : {SIGINT, SIGTERM, SIGHUP}) {
    struct sigaction old {};
    // A signal the caller ignores (nohup, a shell's background job) stays ignored.
    if (::sigaction(sig, nullptr, &old) == 0 && old.sa_handler == SIG_IGN) continue;
    ::sigaction(sig, &sa, nullptr);
  }
}

std::string cannotCreateBeside(const std::string& path) {
  const std::string tmp = createTemporary(fs::path(linkTarget(path)));
  if (tmp.empty()) return std::strerror(errno);
  ::unlink(tmp.c_str());
  return "";
}

}  // namespace gi::io
