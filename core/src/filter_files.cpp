#include "gi/filter_files.h"

#include <algorithm>
#include <cctype>
#include <cstdio>
#include <cerrno>
#include <cstring>
#include <fstream>
#include <stdexcept>

#include "gi/error_map.h"
#include "gi/render.h"

namespace gi {

std::string imageStem(const std::string& path) {
  const size_t dot = path.find_last_of('.'), slash = path.find_last_of('/');
  return dot != std::string::npos && (slash == std::string::npos || dot > slash) ? path.substr(0, dot) : path;
}

std::string lowerExtension(const std::string& path) {
  std::string ext = path.substr(imageStem(path).size());
  std::transform(ext.begin(), ext.end(), ext.begin(), [](unsigned char c) { return char(std::tolower(c)); });
  return ext;
}

std::string stdErrorImagePath(const std::string& imagePath) { return imageStem(imagePath) + "_stderr.png"; }

namespace {

// A picture's path, and its PFM's beside it. The pictures are PNG whatever
// the name says: a name that promises another format (x.jpg, or none) is
// refused before any work rather than holding PNG data under it.
void image(FilterFiles& f, const std::string& png, const std::string& parameter) {
  if (lowerExtension(png) != ".png")
    throw std::invalid_argument(parameter + " '" + png + "': the pictures are written as PNG; give a name ending in .png");
  f.writes.push_back({png, parameter});
  f.writes.push_back({pfmPath(png), parameter});
}

}  // namespace

std::string pfmPath(const std::string& imagePath) { return imageStem(imagePath) + ".pfm"; }

FilterFiles filterFiles(FilterKind kind, const ParamValues& v) {
  FilterFiles f;
  switch (kind) {
    case FilterKind::RayTracedView:
      if (const std::string& p = v.getString("image_path"); !p.empty()) {
        image(f, p, "image_path");
        if (kRenderModes.get(v, "mode") == RenderMode::PathTraced) image(f, stdErrorImagePath(p), "image_path");
      }
      break;
    case FilterKind::HemicubeOfFace:
      // runHemicube's three pictures: the cells at the path, NAME_dff and NAME_nusselt beside it.
      if (const std::string& p = v.getString("image_path"); !p.empty()) {
        image(f, p, "image_path");
        image(f, imageStem(p) + "_dff.png", "image_path");
        image(f, imageStem(p) + "_nusselt.png", "image_path");
      }
      break;
    case FilterKind::Radiosity:
      if (const std::string& p = v.getString("residual_csv"); !p.empty()) f.writes.push_back({p, "residual_csv"});
      if (const std::string& p = v.getString("export_system"); !p.empty())
        for (const char* suffix : {"_F.mtx", "_E.mtx", "_rho.mtx", "_Esys.mtx", "_B.mtx", "_area.mtx"})
          f.writes.push_back({p + suffix, "export_system"});
      break;
    case FilterKind::PhotonMapping:
      if (v.getBool("photon_layer")) f.layers.push_back("Photons");
      break;
    case FilterKind::ErrorMap:
      if (kReferenceSources.get(v, "reference_source") == ReferenceSource::File)
        if (const std::string& p = v.getString("reference_file"); !p.empty()) f.reads.push_back({p, "reference_file"});
      break;
    default: break;
  }
  return f;
}

void writeOutputFiles(const FilterResult& r, const FileWriter& writer) {
  auto write = [&](const std::string& path, const std::function<void(const std::string&)>& to) {
    if (writer) writer(path, to);
    else to(path);
  };
  for (const FilterFile& f : r.files)
    write(f.path, [&](const std::string& to) {
      std::ofstream out(to, std::ios::binary);
      out << f.text;
      out.close();
      if (!out) throw std::runtime_error("cannot write " + to + ": " + std::strerror(errno));
    });
  for (const FilterImage& img : r.images) {
    if (img.path.empty()) continue;
    write(img.path, [&](const std::string& to) { writePng(to, img.image, img.exposure); });
    write(pfmPath(img.path), [&](const std::string& to) { writePfm(to, img.image); });
  }
  for (const std::string& stale : r.staleFiles) std::remove(stale.c_str());  // gone already: nothing to do
}

}  // namespace gi
