#include "gi_plugin.h"

#include <cctype>

#include "gi/filter_files.h"
#include "gi/filter_run.h"
#include "gi/filters.h"
#include "meshlab_bridge.h"
#include "output_files.h"

namespace gi::ml {

namespace {
FilterKind kindOf(compat::FilterId f) { return FilterKind(f); }

// The files a run will write, checked before any work as the CLI checks
// them (io/output_files.h): each can be written, and none is a file the run
// reads, the file a loaded layer came from, or another output.
void checkFiles(FilterKind kind, const FilterInput& in, MeshDocument& md) {
  const FilterFiles plan = filterFiles(kind, in.values);
  if (plan.writes.empty()) return;
  std::vector<files::Named> inputs, outputs;
  for (const NamedFile& f : plan.reads) inputs.push_back({f.path, f.parameter});
  for (MeshModel* m : compat::meshes(md))
    if (!m->fullName().isEmpty()) inputs.push_back({m->fullName().toStdString(), "layer " + m->label().toStdString()});
  for (const NamedFile& f : plan.writes) outputs.push_back({f.path, f.parameter});
  files::check(inputs, outputs);
}
}  // namespace

GiFilterPlugin::GiFilterPlugin(std::string plugin) : plugin_(std::move(plugin)) {}

void GiFilterPlugin::createActions(QObject* owner) {
  for (FilterKind k : pluginFilters(plugin_)) giAddAction(compat::FilterId(k), filterName(compat::FilterId(k)), owner);
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

QString GiFilterPlugin::filterName(compat::FilterId f) const { return QString::fromStdString(filterDesc(kindOf(f)).meshlabName); }

QString GiFilterPlugin::filterInfo(compat::FilterId f) const { return QString::fromStdString(filterDesc(kindOf(f)).info); }

int GiFilterPlugin::giClass(compat::FilterId f) const {
  if (filterDesc(kindOf(f)).writes & WritesImage) return compat::FilterBase::RasterLayer;
  return compat::FilterBase::VertexColoring | compat::FilterBase::Quality;
}

int GiFilterPlugin::giPostCondition(compat::FilterId f) const {
  const unsigned w = filterDesc(kindOf(f)).writes;
  int mask = 0;
  if (w & WritesVertexQuality) mask |= MeshModel::MM_VERTQUALITY;
  if (w & WritesVertexColor) mask |= MeshModel::MM_VERTCOLOR;
  if (w & WritesVertexNormal) mask |= MeshModel::MM_VERTNORMAL;
  if (w & WritesFaceQuality) mask |= MeshModel::MM_FACEQUALITY;
  if (w & WritesFaceColor) mask |= MeshModel::MM_FACECOLOR;
  // postCondition cannot see the parameters: a filter that may refine the mesh
  // makes MeshLab refresh geometry and topology every time.
  if (w & WritesGeometry) mask |= MeshModel::MM_GEOMETRY_AND_TOPOLOGY_CHANGE;
  // A re-run refills its earlier layer in place (addLayers): with as many
  // points as before, only this makes the GUI re-read their positions.
  if (w & WritesLayer) mask |= MeshModel::MM_VERTCOORD | MeshModel::MM_VERTNORMAL;
  return mask;
}

void GiFilterPlugin::giParams(compat::FilterId f, MeshDocument& md, RichParameterList& par) {
  addParams(par, filterSpecs(kindOf(f)), documentDiagonal(md));
}

QString GiFilterPlugin::giApply(compat::FilterId f, MeshDocument& md, const RichParameterList& par, vcg::CallBackPos* cb) {
  const FilterKind kind = kindOf(f);
  const QString name = filterName(f);
  auto logLine = [this](const std::string& s) { giLog(s); };
  QString why;
  guarded(why, logLine, name, [&] {
    BridgeScene b;
    FilterInput in = gatherInput(md, par, kind, b);
    checkFiles(kind, in, md);
    FilterResult r = runFilter(kind, in, Progress(progressFrom(cb)));
    for (const std::string& w : b.warnings) r.stats.warn(w);
    for (const std::string& n : b.notes) r.stats.note(n);
    // Everything is computed: only now does the document change. Files are
    // written whole or not at all (a full disk keeps the file that was there).
    checkResultFits(b, r);  // a layer's attribute of another type under a result's name: refused, nothing written
    writeOutputFiles(r, files::atomicWriter());
    writeResult(b, r);
    addRasters(md, r);
    for (const std::string& n : addLayers(md, r)) r.stats.note(n);
    for (const std::string& line : r.logLines(name.toStdString())) logLine(line);
  });
  return why;
}

}  // namespace gi::ml
