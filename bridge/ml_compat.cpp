#include "ml_compat.h"

namespace gi::ml::compat {

std::vector<MeshModel*> meshes(MeshDocument& md) {
  std::vector<MeshModel*> out;
#ifdef GI_MESHLAB_2025
  for (MeshModel& m : md.meshIterator()) out.push_back(&m);
#else
  for (MeshModel* m : md.meshList)
    if (m) out.push_back(m);
#endif
  return out;
}

MeshModel* addMeshLayer(MeshDocument& md, const QString& label) {
  // 2025.07 also has addNewMesh(const CMeshO&, ...): the file path as a QString picks the same overload in both.
  return md.addNewMesh(QString(), label, false);
}

void addDistance(RichParameterList& out, const QString& name, float def, float max, const QString& label,
                 const QString& help) {
#ifdef GI_MESHLAB_2025
  out.addParam(RichPercentage(name, def, 0.f, max, label, help));
#else
  out.addParam(RichAbsPerc(name, def, 0.f, max, label, help));
#endif
}

void addPoint(RichParameterList& out, const QString& name, const Point3m& def, bool direction, const QString& label,
              const QString& help) {
#ifdef GI_MESHLAB_2025
  if (direction) out.addParam(RichDirection(name, def, label, help));
  else out.addParam(RichPosition(name, def, label, help));
#else
  (void)direction;  // 2020.09 has one class for both
  out.addParam(RichPoint3f(name, vcg::Point3f(float(def[0]), float(def[1]), float(def[2])), label, help));
#endif
}

void FilterAdapter::giLog(const std::string& line) {
  // Through "%s": a line may hold a '%' (a relative error).
#ifdef GI_MESHLAB_2025
  log("%s", line.c_str());
#else
  Log("%s", line.c_str());
#endif
}

void FilterAdapter::giAddAction(FilterId f, const QString& name, QObject* owner) {
#ifdef GI_MESHLAB_2025
  typeList.push_back(f);
  actionList.push_back(new QAction(name, owner));
#else
  typeList << f;
  actionList << new QAction(name, owner);
#endif
}

}  // namespace gi::ml::compat
