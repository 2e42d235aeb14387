#include "filter_radiosity.h"

#include "gi/radiosity.h"
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
         "Each triangle is a patch. <b>Form factors</b> by Monte Carlo ray casting: from stratified points on patch i, "
         "rays in cosine-weighted directions; the fraction landing on patch j is F<sub>ij</sub> (visibility "
         "included). <b>Direct light</b> is computed apart, with the exact point-to-triangle form factor to each "
         "emitter and shadow rays (small lights would be missed by the F rays), and the solver finds the reflected "
         "radiosity. <b>Solvers</b>: Jacobi (one sweep = one more bounce), Gauss-Seidel (uses new values at once: "
         "fewer sweeps), progressive refinement (Cohen et al. 1988: shoot the patch with the most unshot power). "
         "<b>Bounces</b> 0 shows direct light only, 1, 2, 3... the course's sequence; -1 iterates to the "
         "tolerance. The form factors are kept in a sparse matrix while it fits the memory budget; beyond it, "
         "progressive refinement computes them on the fly.<br>"
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
int FilterRadiosityPlugin::postCondition(QAction*) const {
  return MeshModel::MM_VERTCOLOR | MeshModel::MM_VERTQUALITY | MeshModel::MM_FACECOLOR | MeshModel::MM_FACEQUALITY;
}

void FilterRadiosityPlugin::initParameterSet(QAction*, MeshDocument& md, RichParameterList& par) {
  ml::addParams(par, specs(), ml::documentDiagonal(md));
}

bool FilterRadiosityPlugin::applyFilter(QAction* a, MeshDocument& md, const RichParameterList& par, vcg::CallBackPos* cb) {
  auto logLine = [this](const std::string& s) { Log("%s", s.c_str()); };
  return ml::guarded(errorMessage, logLine, filterName(ID(a)), [&] {
    ml::PreparedRun run = ml::prepare(md, par, specs(), true);
    const RadiosityOptions opt = RadiosityOptions::fromParams(run.values);
    auto caster = makeEmbreeCaster(run.bridge.scene);
    RadiosityResult r = solveRadiosity(run.bridge.scene, *caster, opt, Progress(ml::progressFrom(cb)));
    ml::writeRadiosity(run, r.Bvertex, r.B, run.values.getBool("face_output"), r.stats);
    logLine(run.report.summary() + "; " + run.setupLog);
    logLine(r.stats.line("GI: Radiosity"));
  });
}

MESHLAB_PLUGIN_NAME_EXPORTER(FilterRadiosityPlugin)
