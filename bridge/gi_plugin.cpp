#include "gi_plugin.h"

#include <cctype>

#include "gi/filter_run.h"
#include "gi/filters.h"
#include "meshlab_bridge.h"

namespace gi::ml {

namespace {
FilterKind kindOf(MeshFilterInterface::FilterIDType f) { return FilterKind(f); }
}  // namespace

GiFilterPlugin::GiFilterPlugin(std::string plugin) : plugin_(std::move(plugin)) {}

void GiFilterPlugin::createActions(QObject* owner) {
  for (FilterKind k : pluginFilters(plugin_)) typeList << FilterIDType(k);
  for (FilterIDType t : types()) actionList << new QAction(filterName(t), owner);
}

QString GiFilterPlugin::pluginName() const {
  // "filter_ambient" -> "FilterAmbientGI"
  std::string n;
  bool up = true;
  for (char c : plugin_) {
    if (c == '_') { up = true; continue; }
    n += up ? char(std::toupper(static_cast<unsigned char>(c))) : c;
    up = false;
  }
  return QString::fromStdString(n + "GI");
}

QString GiFilterPlugin::filterName(FilterIDType f) const { return QString::fromStdString(filterDesc(kindOf(f)).meshlabName); }

QString GiFilterPlugin::filterInfo(FilterIDType f) const { return QString::fromStdString(filterDesc(kindOf(f)).info); }

MeshFilterInterface::FilterClass GiFilterPlugin::getClass(QAction* a) {
  if (filterDesc(kindOf(ID(a))).writes & WritesImage) return FilterClass(MeshFilterInterface::RasterLayer);
  return FilterClass(MeshFilterInterface::VertexColoring | MeshFilterInterface::Quality);
}

MeshFilterInterface::FILTER_ARITY GiFilterPlugin::filterArity(QAction*) const { return VARIABLE; }

int GiFilterPlugin::getPreConditions(QAction*) const { return MeshModel::MM_NONE; }

int GiFilterPlugin::postCondition(QAction* a) const {
  const unsigned w = filterDesc(kindOf(ID(a))).writes;
  int mask = 0;
  if (w & WritesVertexQuality) mask |= MeshModel::MM_VERTQUALITY;
  if (w & WritesVertexColor) mask |= MeshModel::MM_VERTCOLOR;
  if (w & WritesVertexNormal) mask |= MeshModel::MM_VERTNORMAL;
  if (w & WritesFaceQuality) mask |= MeshModel::MM_FACEQUALITY;
  if (w & WritesFaceColor) mask |= MeshModel::MM_FACECOLOR;
  // postCondition cannot see the parameters: a filter that may refine the mesh
  // makes MeshLab refresh geometry and topology every time.
  if (w & WritesGeometry) mask |= MeshModel::MM_GEOMETRY_AND_TOPOLOGY_CHANGE;
  return mask;
}

void GiFilterPlugin::initParameterSet(QAction* a, MeshDocument& md, RichParameterList& par) {
  addParams(par, filterSpecs(kindOf(ID(a))), documentDiagonal(md));
}

bool GiFilterPlugin::applyFilter(QAction* a, MeshDocument& md, const RichParameterList& par, vcg::CallBackPos* cb) {
  const FilterKind kind = kindOf(ID(a));
  const QString name = filterName(ID(a));
  auto logLine = [this](const std::string& s) { Log("%s", s.c_str()); };
  return guarded(errorMessage, logLine, name, [&] {
    BridgeScene b;
    FilterInput in = gatherInput(md, par, kind, b);
    FilterResult r = runFilter(kind, in, Progress(progressFrom(cb)));
    // Everything is computed: only now does the document change.
    writeOutputFiles(r);
    writeResult(b, r);
    addRasters(md, r);
    for (const std::string& line : r.logLines(name.toStdString())) logLine(line);
  });
}

}  // namespace gi::ml
