#include "filter_reference.h"

#include "gi/filters.h"
#include "gi/output.h"
#include "gi/pathtrace.h"
#include "meshlab_bridge.h"

using namespace gi;

namespace {
std::vector<ParamSpec> specs() { return filterSpecs(FilterKind::PathTracedReference); }
}  // namespace

FilterReferencePlugin::FilterReferencePlugin() {
  typeList << FP_PATH_TRACED_REFERENCE;
  for (FilterIDType t : types()) actionList << new QAction(filterName(t), this);
}

QString FilterReferencePlugin::pluginName() const { return "FilterReferenceGI"; }

QString FilterReferencePlugin::filterName(FilterIDType) const { return "GI: Path Traced Reference"; }

QString FilterReferencePlugin::filterInfo(FilterIDType) const {
  return "A <b>reference solution</b> of the rendering equation (Kajiya 1986) at every vertex, for diffuse "
         "surfaces: the yardstick against which radiosity, photon mapping and sky lighting are measured. From each "
         "vertex, paths are traced: at every bounce the lights are sampled directly (next-event estimation) and "
         "combined with the cosine-sampled direction by <b>multiple importance sampling</b> (Veach 1997); paths end "
         "by <b>Russian roulette</b>, which keeps the estimate unbiased. Lights: the emitter faces, a uniform sky, "
         "a sun disk (soft shadows) and a point or spot light. <b>Mirrors and glass</b> (layers named as in 'GI: "
         "Photon Mapping') are followed specularly (Fresnel, refraction, total internal reflection): caustics "
         "converge, slowly, where photon mapping is fast.<br>"
         "Output: vertex <b>quality</b> = luminance of the radiosity B (W/m<sup>2</sup>), vertex <b>colour</b> = "
         "sRGB(exposure &times; B), and the per-vertex attributes <i>StdError</i> (standard error of the quality, an "
         "honest Monte Carlo error bar) and <i>Paths</i>. With a target relative error, each vertex traces paths "
         "until its error bar is small enough.";
}

MeshFilterInterface::FilterClass FilterReferencePlugin::getClass(QAction*) {
  return FilterClass(MeshFilterInterface::VertexColoring | MeshFilterInterface::Quality);
}
MeshFilterInterface::FILTER_ARITY FilterReferencePlugin::filterArity(QAction*) const { return VARIABLE; }
int FilterReferencePlugin::getPreConditions(QAction*) const { return MeshModel::MM_NONE; }
int FilterReferencePlugin::postCondition(QAction*) const { return MeshModel::MM_VERTCOLOR | MeshModel::MM_VERTQUALITY; }

void FilterReferencePlugin::initParameterSet(QAction*, MeshDocument& md, RichParameterList& par) {
  ml::addParams(par, specs(), ml::documentDiagonal(md));
}

bool FilterReferencePlugin::applyFilter(QAction* a, MeshDocument& md, const RichParameterList& par, vcg::CallBackPos* cb) {
  auto logLine = [this](const std::string& s) { Log("%s", s.c_str()); };
  return ml::guarded(errorMessage, logLine, filterName(ID(a)), [&] {
    ml::PreparedRun run = ml::prepare(md, par, specs(), true);
    const PathTraceOptions opt = PathTraceOptions::fromParams(run.values, run.bridge.scene.origin);
    auto caster = makeEmbreeCaster(run.bridge.scene);
    PathTraceResult r = pathTrace(run.bridge.scene, *caster, opt, Progress(ml::progressFrom(cb)));
    ml::writeRadiosity(run, r.B, {}, false, r.stats);
    ml::writeVertexScalarAttribute(run.bridge, "StdError", r.stdError);
    std::vector<float> paths(r.samples.begin(), r.samples.end());
    ml::writeVertexScalarAttribute(run.bridge, "Paths", paths);
    logLine(run.report.summary() + "; " + run.setupLog);
    logLine(r.stats.line("GI: Path Traced Reference"));
  });
}

MESHLAB_PLUGIN_NAME_EXPORTER(FilterReferencePlugin)
