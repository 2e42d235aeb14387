#include "output_files.h"

#include <sys/stat.h>
#include <unistd.h>

#include <cerrno>
#include <climits>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <map>
#include <stdexcept>

#include "atomic_file.h"

namespace gi::files {

namespace fs = std::filesystem;

namespace {

// What makes two paths one file: an existing file's device and inode (so
// hard links and every spelling of its path agree), else the absolute path
// with symbolic links and "." and ".." resolved as far as it exists.
std::string identity(const std::string& path) {
  const std::string target = io::linkTarget(path);
  struct stat st {};
  if (::stat(target.c_str(), &st) == 0)
    return "file " + std::to_string(st.st_dev) + ":" + std::to_string(st.st_ino);
  std::error_code ec;
  const fs::path absolute = fs::absolute(target, ec);
  const fs::path canonical = fs::weakly_canonical(absolute, ec);
  return "path " + (ec ? absolute.lexically_normal() : canonical).string();
}

bool exists(const std::string& path) {
  struct stat st {};
  return ::stat(path.c_str(), &st) == 0;
}

void checkWritable(const Named& out, std::map<std::string, std::string>& folders) {
  if (out.path.empty()) throw std::invalid_argument(out.what + " is empty: give a file name");
  const std::string cannot = "cannot write " + out.path + (out.what.empty() ? "" : " (" + out.what + ")") + ": ";
  const std::string target = io::linkTarget(out.path);
  struct stat st {};
  const bool there = ::stat(target.c_str(), &st) == 0;
  if (there && S_ISDIR(st.st_mode)) throw std::invalid_argument(cannot + "it is a directory");
  if (there && access(target.c_str(), W_OK) != 0) throw std::invalid_argument(cannot + std::strerror(errno));
  if (there && !S_ISREG(st.st_mode)) return;  // a device or a pipe, written in place
  if (!there && target.size() >= PATH_MAX)
    throw std::invalid_argument(cannot + "the path is " + std::to_string(target.size()) + " bytes long, at most " +
                                std::to_string(PATH_MAX - 1) + " are taken");
  const fs::path parent = fs::path(target).parent_path().empty() ? fs::path(".") : fs::path(target).parent_path();
  std::error_code ec;
  const fs::file_status pst = fs::status(parent, ec);
  if (!fs::exists(pst)) throw std::invalid_argument(cannot + "the folder " + parent.string() + " does not exist");
  if (!fs::is_directory(pst)) throw std::invalid_argument(cannot + parent.string() + " is not a folder");
  // A name the folder cannot hold (ENAMETOOLONG) would otherwise fail only
  // when the result is written, after the computation.
  if (!there) {
    const size_t nameBytes = fs::path(target).filename().string().size();
    const long nameMax = ::pathconf(parent.c_str(), _PC_NAME_MAX);
    if (nameMax > 0 && nameBytes > size_t(nameMax))
      throw std::invalid_argument(cannot + "its name is " + std::to_string(nameBytes) + " bytes long, and the folder " +
                                  parent.string() + " takes names of at most " + std::to_string(nameMax));
  }
  // The file is written to a temporary beside it and renamed: the folder must take a new file.
  auto [it, fresh] = folders.emplace(parent.string(), "");
  if (fresh) it->second = io::cannotCreateBeside(target);
  if (!it->second.empty())
    throw std::invalid_argument(cannot + "the folder " + parent.string() + " takes no new file (" + it->second + ")");
}

}  // namespace

std::string readTextFile(const std::string& path, const std::string& what, size_t maxBytes) {
  const std::string name = "the " + what + " " + (path.empty() ? std::string("''") : path);
  std::error_code ec;
  const fs::file_status st = fs::status(path, ec);
  if (path.empty() || st.type() == fs::file_type::not_found) throw std::invalid_argument(name + " does not exist");
  if (ec) throw std::invalid_argument(name + " cannot be read (" + ec.message() + ")");
  if (fs::is_directory(st)) throw std::invalid_argument(name + " is a folder, not a file");
  if (!fs::is_regular_file(st)) throw std::invalid_argument(name + " is not a regular file (a pipe or a device)");
  const uintmax_t size = fs::file_size(path, ec);
  if (ec) throw std::invalid_argument(name + " cannot be read (" + ec.message() + ")");
  if (size > maxBytes) throw std::invalid_argument(name + " is larger than " + std::to_string(maxBytes >> 20) + " MB");
  std::ifstream f(path, std::ios::binary);
  std::string text(size_t(size), '\0');
  if (!f || !f.read(text.data(), std::streamsize(size)) || f.peek() != std::char_traits<char>::eof())
    throw std::invalid_argument(name + " cannot be read" + (errno ? " (" + std::string(std::strerror(errno)) + ")" : std::string()) +
                                " or changed while it was read");
  return text;
}

void checkWritable(const Named& out) {
  std::map<std::string, std::string> folders;
  checkWritable(out, folders);
}

void check(const std::vector<Named>& inputs, const std::vector<Named>& outputs) {
  std::map<std::string, std::string> folders;  // folder -> why it takes no new file ("" if it does)
  for (const Named& out : outputs) checkWritable(out, folders);
  std::map<std::string, std::pair<const Named*, bool>> seen;  // identity -> the file, whether an input
  for (const Named& in : inputs)
    if (exists(in.path)) seen.emplace(identity(in.path), std::make_pair(&in, true));
  for (const Named& out : outputs) {
    const auto [it, fresh] = seen.emplace(identity(out.path), std::make_pair(&out, false));
    if (fresh) continue;
    const Named& other = *it->second.first;
    auto named = [](const Named& f) { return f.path + (f.what.empty() ? "" : " (" + f.what + ")"); };
    throw std::invalid_argument("the output " + named(out) + " would overwrite the " +
                                (it->second.second ? "input " : "output ") + named(other));
  }
}

FileWriter atomicWriter() {
  return [](const std::string& path, const std::function<void(const std::string&)>& write) {
    io::writeAtomically(path, write);
  };
}

}  // namespace gi::files
