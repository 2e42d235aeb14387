// gi-scenes OUTDIR [NAME...]: writes the canonical test scenes as NAME.ply
// (scenes of several layers, like caustic_cornell, as one file per layer).
// Face colour = sRGB of rho, face quality = 1 on emitters (the inputs the
// filters read); vertex colour shows rho, vertex quality is 0.
// gi-scenes scan BASE LEVELS OUT.ply [AMPLITUDE FREQUENCY OCTAVES]: a
// generated scan (gi/scan.h), BASE Loop-subdivided LEVELS times and displaced.
// gi-scenes scanroom BASE TRIANGLES OUT.ply [SEED]: that scan standing in a
// room with a ceiling light and a window (gi::scenes::scanRoom), about
// TRIANGLES triangles in all, emitters marked like the canonical scenes'.
#include <algorithm>
#include <cstdio>
#include <exception>
#include <filesystem>
#include <stdexcept>
#include <string>
#include <vector>

#include "gi/color.h"
#include "gi/scene_setup.h"
#include "gi/scan.h"
#include "gi/scenes.h"
#include "mesh_io.h"

namespace {

// Face colour = sRGB of rho, face quality = 1 on emitters, vertex colour = rho.
void writeSceneFile(const std::string& path, const gi::scenes::SceneFile& sf) {
  const auto vertexRho = gi::faceToVertex(sf.scene, sf.scene.rho);
  std::vector<gi::Rgb8> colour;
  colour.reserve(vertexRho.size());
  for (const auto& r : vertexRho) colour.push_back(gi::displayMap(r, 1.f));
  const std::vector<float> quality(sf.scene.vertexCount(), 0.f);
  gi::io::writePly(path, sf.scene, sf.attrs, quality, colour);
  std::printf("%s: %zu vertices, %zu triangles\n", path.c_str(), sf.scene.vertexCount(), sf.scene.faceCount());
}

// A whole non-negative decimal number (std::stoull takes "-5" as 2^64 - 5
// and "12abc" as 12).
unsigned long long parseCount(const std::string& text, const char* what) {
  const bool digits = !text.empty() && text.size() <= 19 &&
                      std::all_of(text.begin(), text.end(), [](char c) { return c >= '0' && c <= '9'; });
  if (!digits) throw std::invalid_argument(std::string(what) + " must be a whole number >= 0, not '" + text + "'");
  return std::stoull(text);
}

int writeScanRoom(int argc, char** argv) {
  if (argc < 5) {
    std::fprintf(stderr, "usage: gi-scenes scanroom BASE TRIANGLES OUT.ply [SEED]\n");
    return 2;
  }
  gi::scenes::ScanOptions o;
  if (argc > 5) {
    const unsigned long long seed = parseCount(argv[5], "SEED");
    if (seed > 0xffffffffull) throw std::invalid_argument("SEED must be below 2^32");
    o.seed = uint32_t(seed);
  }
  const size_t triangles = size_t(parseCount(argv[3], "TRIANGLES"));
  const gi::io::LoadedMesh base = gi::io::loadMesh(argv[2]);
  writeSceneFile(argv[4], gi::scenes::scanRoom(base.scene, triangles, o));
  return 0;
}

int writeScan(int argc, char** argv) {
  if (argc < 5) {
    std::fprintf(stderr, "usage: gi-scenes scan BASE LEVELS OUT.ply [AMPLITUDE FREQUENCY OCTAVES]\n");
    return 2;
  }
  gi::scenes::ScanOptions o;
  o.levels = std::stoi(argv[3]);
  if (argc > 5) o.amplitude = std::stod(argv[5]);
  if (argc > 6) o.frequency = std::stod(argv[6]);
  if (argc > 7) o.octaves = std::stoi(argv[7]);
  const gi::io::LoadedMesh base = gi::io::loadMesh(argv[2]);
  const gi::Scene s = gi::scenes::displacedScan(base.scene, o);
  gi::io::writePly(argv[4], s, gi::MeshAttributes{}, {}, {});
  std::printf("%s: %zu vertices, %zu triangles\n", argv[4], s.vertexCount(), s.faceCount());
  return 0;
}

}  // namespace

int main(int argc, char** argv) {
  if (argc > 1 && (std::string(argv[1]) == "scan" || std::string(argv[1]) == "scanroom")) {
    try {
      return std::string(argv[1]) == "scan" ? writeScan(argc, argv) : writeScanRoom(argc, argv);
    } catch (const std::exception& e) {
      std::fprintf(stderr, "gi-scenes: %s\n", e.what());
      return 1;
    }
  }
  if (argc < 2 || std::string(argv[1]) == "-h" || std::string(argv[1]) == "--help") {
    std::printf("usage: gi-scenes OUTDIR [NAME...]\n       gi-scenes scan BASE LEVELS OUT.ply [AMPLITUDE FREQUENCY OCTAVES]\n"
                "       gi-scenes scanroom BASE TRIANGLES OUT.ply [SEED]\nscenes:");
    for (const auto& n : gi::scenes::names()) std::printf(" %s", n.c_str());
    std::printf("\n");
    return argc < 2 ? 2 : 0;
  }
  const std::filesystem::path dir(argv[1]);
  std::vector<std::string> names(argv + 2, argv + argc);
  if (names.empty()) names = gi::scenes::names();
  try {
    std::filesystem::create_directories(dir);
    for (const auto& name : names) {
      for (const auto& layer : gi::scenes::layersByName(name)) writeSceneFile((dir / layer.name).string(), layer.file);
    }
  } catch (const std::exception& e) {
    std::fprintf(stderr, "gi-scenes: %s\n", e.what());
    return 1;
  }
  return 0;
}
