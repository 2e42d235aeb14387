#include "filter_photonmap.h"

#include "gi/photon.h"
#include "gi/filters.h"
#include "meshlab_bridge.h"

using namespace gi;

namespace {
std::vector<ParamSpec> specs() { return filterSpecs(FilterKind::PhotonMapping); }
}  // namespace

FilterPhotonMapPlugin::FilterPhotonMapPlugin() {
  typeList << FP_PHOTON_MAPPING;
  for (FilterIDType t : types()) actionList << new QAction(filterName(t), this);
}

QString FilterPhotonMapPlugin::pluginName() const { return "FilterPhotonMapGI"; }

QString FilterPhotonMapPlugin::filterName(FilterIDType) const { return "GI: Photon Mapping"; }

QString FilterPhotonMapPlugin::filterInfo(FilterIDType) const {
  return "<b>Photon mapping</b> (Jensen 1996). Pass 1: photons leave the emitters in proportion to their power "
         "(cosine-distributed directions), bounce on diffuse surfaces with Russian roulette (survival probability = "
         "the largest reflectance channel, power scaled by &rho;/p so the estimate stays unbiased), and are stored "
         "where they land in a kd-tree (nanoflann). Pass 2: at every vertex the irradiance is estimated from the "
         "k nearest photons on the same side of the surface, <i>H &asymp; &sum; &Phi;<sub>p</sub> / (&pi; "
         "r<sub>k</sub><sup>2</sup>)</i>, and the radiosity is <i>B = E + &rho; H</i>. More photons: less noise; "
         "larger k: less noise but more blur.<br>"
         "By default the <b>direct light</b> is computed apart at every vertex by light sampling with shadow rays "
         "(soft shadows, no photon noise) and only photons that bounced at least once give the indirect light "
         "(Jensen's split). The optional <b>final gather</b> reads the photon map where cosine-weighted rays from the "
         "vertex land, which smooths the indirect light further.<br>"
         "Emitters, reflectance and output conventions are those of 'GI: Radiosity', so the two compare directly.";
}

MeshFilterInterface::FilterClass FilterPhotonMapPlugin::getClass(QAction*) {
  return FilterClass(MeshFilterInterface::VertexColoring | MeshFilterInterface::Quality);
}
MeshFilterInterface::FILTER_ARITY FilterPhotonMapPlugin::filterArity(QAction*) const { return VARIABLE; }
int FilterPhotonMapPlugin::getPreConditions(QAction*) const { return MeshModel::MM_NONE; }
int FilterPhotonMapPlugin::postCondition(QAction*) const { return MeshModel::MM_VERTCOLOR | MeshModel::MM_VERTQUALITY; }

void FilterPhotonMapPlugin::initParameterSet(QAction*, MeshDocument& md, RichParameterList& par) {
  ml::addParams(par, specs(), ml::documentDiagonal(md));
}

bool FilterPhotonMapPlugin::applyFilter(QAction* a, MeshDocument& md, const RichParameterList& par, vcg::CallBackPos* cb) {
  auto logLine = [this](const std::string& s) { Log("%s", s.c_str()); };
  return ml::guarded(errorMessage, logLine, filterName(ID(a)), [&] {
    ml::PreparedRun run = ml::prepare(md, par, specs(), true);
    const PhotonOptions opt = PhotonOptions::fromParams(run.values);
    auto caster = makeEmbreeCaster(run.bridge.scene);
    VertexRadiometry r = computePhotonMap(run.bridge.scene, *caster, opt, Progress(ml::progressFrom(cb)));
    ml::writeRadiometry(run, r);
    logLine(run.report.summary() + "; " + run.setupLog);
    logLine(r.stats.line("GI: Photon Mapping"));
  });
}

MESHLAB_PLUGIN_NAME_EXPORTER(FilterPhotonMapPlugin)
