#include "filter_radiosity.h"

#include "gi/direct.h"
#include "gi/filters.h"
#include "meshlab_bridge.h"

using namespace gi;

namespace {
std::vector<ParamSpec> specs() { return filterSpecs(FilterKind::Radiosity); }
}  // namespace

FilterRadiosityPlugin::FilterRadiosityPlugin() {
  typeList << FP_RADIOSITY;
  for (FilterIDType t : types()) actionList << new QAction(filterName(t), this);
}

QString FilterRadiosityPlugin::pluginName() const { return "FilterRadiosityGI"; }

QString FilterRadiosityPlugin::filterName(FilterIDType) const { return "GI: Radiosity"; }

QString FilterRadiosityPlugin::filterInfo(FilterIDType) const {
  return "<b>Radiosity</b> of diffuse (Lambertian) surfaces: the radiosity equation "
         "<i>B<sub>i</sub> = E<sub>i</sub> + &rho;<sub>i</sub> &sum;<sub>j</sub> F<sub>ij</sub> B<sub>j</sub></i> "
         "in RGB, with B the radiosity (W/m<sup>2</sup>), E the emitted radiosity, &rho; the reflectance and "
         "F<sub>ij</sub> the form factor (the fraction of the energy leaving patch i that reaches patch j).<br>"
         "This version computes the <b>zero-bounce</b> solution: <i>B = E + &rho; H<sub>direct</sub></i>, the "
         "direct irradiance H from the emitters with exact shadows, estimated at every vertex with shadow rays to "
         "points sampled on the emitters in proportion to their power (soft shadows from area lights).<br>"
         "<b>Emitters</b>: select the light's faces, or give them a face quality above a threshold. "
         "<b>Reflectance</b>: face colour, else vertex colour, else a constant (sRGB converted to linear).<br>"
         "Output: vertex <b>quality</b> = luminance of B (W/m<sup>2</sup>); vertex <b>colour</b> = "
         "sRGB(exposure &times; B). Every layer of the scene receives its result.";
}

MeshFilterInterface::FilterClass FilterRadiosityPlugin::getClass(QAction*) {
  return FilterClass(MeshFilterInterface::VertexColoring | MeshFilterInterface::Quality);
}
MeshFilterInterface::FILTER_ARITY FilterRadiosityPlugin::filterArity(QAction*) const { return VARIABLE; }
int FilterRadiosityPlugin::getPreConditions(QAction*) const { return MeshModel::MM_NONE; }
int FilterRadiosityPlugin::postCondition(QAction*) const { return MeshModel::MM_VERTCOLOR | MeshModel::MM_VERTQUALITY; }

void FilterRadiosityPlugin::initParameterSet(QAction*, MeshDocument& md, RichParameterList& par) {
  ml::addParams(par, specs(), ml::documentDiagonal(md));
}

bool FilterRadiosityPlugin::applyFilter(QAction* a, MeshDocument& md, const RichParameterList& par, vcg::CallBackPos* cb) {
  auto logLine = [this](const std::string& s) { Log("%s", s.c_str()); };
  return ml::guarded(errorMessage, logLine, filterName(ID(a)), [&] {
    ml::PreparedRun run = ml::prepare(md, par, specs(), true);
    const DirectOptions opt = DirectOptions::fromParams(run.values);
    auto caster = makeEmbreeCaster(run.bridge.scene);
    VertexRadiometry r = computeDirect(run.bridge.scene, *caster, opt, Progress(ml::progressFrom(cb)));
    ml::writeRadiometry(run, r);
    logLine(run.report.summary() + "; " + run.setupLog);
    logLine(r.stats.line("GI: Radiosity"));
  });
}

MESHLAB_PLUGIN_NAME_EXPORTER(FilterRadiosityPlugin)
