#include "filter_ambient.h"

#include "gi/ambient.h"
#include "gi/filters.h"
#include "gi/output.h"
#include "meshlab_bridge.h"

using namespace gi;

namespace {
AmbientMode modeOf(int id) {
  return id == FilterAmbientPlugin::FP_AMBIENT_OBSCURANCE ? AmbientMode::Obscurance
         : id == FilterAmbientPlugin::FP_SKY_LIGHTING     ? AmbientMode::Sky
                                                          : AmbientMode::Occlusion;
}
std::vector<ParamSpec> specsOf(int id) {
  return filterSpecs(id == FilterAmbientPlugin::FP_AMBIENT_OBSCURANCE ? FilterKind::AmbientObscurance
                     : id == FilterAmbientPlugin::FP_SKY_LIGHTING     ? FilterKind::SkyLighting
                                                                      : FilterKind::AmbientOcclusion);
}
}  // namespace

FilterAmbientPlugin::FilterAmbientPlugin() {
  typeList << FP_AMBIENT_OCCLUSION << FP_AMBIENT_OBSCURANCE << FP_SKY_LIGHTING;
  for (FilterIDType t : types()) actionList << new QAction(filterName(t), this);
}

QString FilterAmbientPlugin::pluginName() const { return "FilterAmbientGI"; }

QString FilterAmbientPlugin::filterName(FilterIDType f) const {
  switch (f) {
    case FP_AMBIENT_OCCLUSION: return "GI: Ambient Occlusion";
    case FP_AMBIENT_OBSCURANCE: return "GI: Ambient Obscurance";
    case FP_SKY_LIGHTING: return "GI: Sky Lighting";
  }
  return "";
}

QString FilterAmbientPlugin::filterInfo(FilterIDType f) const {
  switch (f) {
    case FP_AMBIENT_OCCLUSION:
      return "Per-vertex <b>ambient occlusion</b> by ray casting (Embree): the cosine-weighted fraction of the "
             "hemisphere above each vertex from which the sky is visible,<br>"
             "<i>AO(p) = 1/&pi; &int;<sub>H</sub> V(p,&omega;) cos&theta; d&omega;</i>, 1 = fully open, 0 = closed.<br>"
             "Directions are cosine-distributed (so each ray counts 0 or 1) and come from an Owen-scrambled Sobol "
             "sequence per vertex: the error falls faster than plain Monte Carlo's N<sup>-1/2</sup>. "
             "With a target error each vertex stops as soon as its own standard error is small enough. "
             "The result goes to vertex <b>quality</b> (the AO value) and vertex <b>colour</b> (grey, AO x 255).<br>"
             "Unlike MeshLab's depth-map 'Ambient Occlusion' it needs no GPU, is seeded and deterministic, and its "
             "values span [0,1] (MeshLab's top out at 0.25). Other visible layers can occlude (Scene extent).";
    case FP_AMBIENT_OBSCURANCE:
      return "Per-vertex <b>ambient obscurance</b> (Zhukov, Iones and Kronin 1998; Iones et al. 2003): like ambient "
             "occlusion, but a hit at distance d only darkens by <i>1 - &rho;(d)</i> with "
             "<i>&rho;(d) = min(1, d/d<sub>max</sub>)<sup>k</sup></i>, so far geometry matters less and open scenes "
             "and interiors both look natural. Output: quality = obscurance in [0,1], colour = grey.";
    case FP_SKY_LIGHTING:
      return "Per-vertex <b>irradiance</b> (W/m<sup>2</sup>) from a uniform sky plus a sun: "
             "<i>E = E<sub>sky</sub> AO + E<sub>sun</sub> &lang;V cos&rang;<sub>sun disk</sub></i>. Soft shadows come "
             "from shadow rays spread over the sun's disk (distributed ray tracing). Quality = luminance of E; "
             "colour = sRGB(exposure &times; E), exposure 0 = automatic.";
  }
  return "";
}

MeshFilterInterface::FilterClass FilterAmbientPlugin::getClass(QAction*) {
  return FilterClass(MeshFilterInterface::VertexColoring | MeshFilterInterface::Quality);
}
MeshFilterInterface::FILTER_ARITY FilterAmbientPlugin::filterArity(QAction*) const { return VARIABLE; }
int FilterAmbientPlugin::getPreConditions(QAction*) const { return MeshModel::MM_NONE; }
int FilterAmbientPlugin::postCondition(QAction*) const {
  return MeshModel::MM_VERTCOLOR | MeshModel::MM_VERTQUALITY | MeshModel::MM_VERTNORMAL;
}

void FilterAmbientPlugin::initParameterSet(QAction* a, MeshDocument& md, RichParameterList& par) {
  ml::addParams(par, specsOf(ID(a)), ml::documentDiagonal(md));
}

bool FilterAmbientPlugin::applyFilter(QAction* a, MeshDocument& md, const RichParameterList& par, vcg::CallBackPos* cb) {
  const int id = ID(a);
  auto logLine = [this](const std::string& s) { Log("%s", s.c_str()); };
  return ml::guarded(errorMessage, logLine, filterName(id), [&] {
    const auto specs = specsOf(id);
    ml::PreparedRun run = ml::prepare(md, par, specs, false);
    const AmbientOptions opt = AmbientOptions::fromParams(modeOf(id), run.values);
    auto caster = makeEmbreeCaster(run.bridge.scene, opt.batch);
    AmbientResult r = computeAmbient(run.bridge.scene, *caster, opt, Progress(ml::progressFrom(cb)));
    // Everything is computed: only now does the mesh change.
    if (opt.mode == AmbientMode::Sky) {
      VertexOutput out = radiometricOutput(run.bridge.scene, r.rgb, run.values.getFloat("exposure"));
      ml::writeVertexResults(run.bridge, out.quality, out.displayColors());
      r.stats.add("exposure", out.exposure);
    } else {
      const int mapping = opt.mode == AmbientMode::Occlusion ? run.values.getInt("color_mapping") : 0;
      ml::writeVertexResults(run.bridge, r.value,
                             mapping == int(AOColorMapping::Grey) ? greyColors(r.value) : std::vector<Rgb8>{});
      if (mapping == int(AOColorMapping::MultiplyColor)) ml::multiplyVertexColors(run.bridge, r.value);
      if (opt.bentNormals)
        ml::writeVertexVectorAttribute(run.bridge, "BentNormal", r.bentNormal,
                                       run.values.getBool("bent_normals_to_vertex_normals"));
    }
    logLine(run.report.summary());
    logLine(r.stats.line(filterName(id).toStdString()));
  });
}

MESHLAB_PLUGIN_NAME_EXPORTER(FilterAmbientPlugin)
