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
  return "<b>Photon mapping</b> (Jensen 1996) carries the light radiosity cannot: <b>caustics</b>, light focused "
         "by a mirror or glass onto a diffuse surface (paths L S+ D).<br>"
         "<b>Pass 1</b>: photons leave the lights in proportion to their power (emitter faces, and an optional point "
         "or spot light), bounce on diffuse surfaces with Russian roulette (survival = the largest reflectance "
         "channel, power scaled by &rho;/p: unbiased), reflect on <b>mirrors</b> and reflect or refract through "
         "<b>glass</b> (Fresnel reflectance, Snell's law, total internal reflection), and are stored where they land "
         "on diffuse faces: photons that came through mirrors or glass only in the <b>caustic map</b>, those that "
         "bounced off a diffuse surface before in the <b>global map</b> (kd-trees, nanoflann). The caustic photons "
         "are shot only towards the mirror and glass objects (Jensen's projection maps), so small ones still get "
         "many.<br>"
         "<b>Pass 2</b>: at every vertex, <i>B = E + &rho; H</i> with the irradiance H from the direct light "
         "(explicit light sampling with shadow rays: soft shadows), the caustic map (k nearest caustic photons, cone "
         "filter) and the global map (k nearest, <i>H &asymp; &sum; &Phi;<sub>p</sub> / (&pi; r<sub>k</sub>"
         "<sup>2</sup>)</i>), or a <b>final gather</b> that reads it where cosine rays from the vertex land. "
         "<b>Progressive</b> photon mapping (Hachisuka et al. 2008) shoots passes of photons and shrinks a per-vertex "
         "radius (alpha = 2/3) so the estimate converges.<br>"
         "<b>Marking mirrors and glass</b>: load them as their own layers and name them (file name or Layer dialog "
         "rename) to match 'Mirror layers' / 'Glass layers' (default: any name containing 'mirror' / 'glass'); set "
         "'Scene extent' to all visible layers. Glass objects must be closed meshes with outward normals. Vertices "
         "on mirrors and glass get no diffuse radiosity (0).<br>"
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
    const PhotonOptions opt = PhotonOptions::fromParams(run.values, run.bridge.scene.origin);
    auto caster = makeEmbreeCaster(run.bridge.scene);
    VertexRadiometry r = computePhotonMap(run.bridge.scene, *caster, opt, Progress(ml::progressFrom(cb)));
    ml::writeRadiometry(run, r);
    logLine(run.report.summary() + "; " + run.setupLog);
    logLine(r.stats.line("GI: Photon Mapping"));
  });
}

MESHLAB_PLUGIN_NAME_EXPORTER(FilterPhotonMapPlugin)
