#include "filter_radiosity.h"

#include "gi/output.h"
#include "gi/radiosity.h"
#include "gi/filters.h"
#include "meshlab_bridge.h"

using namespace gi;

namespace {
FilterKind kindOf(int id) {
  return id == FilterRadiosityPlugin::FP_FORM_FACTORS_OF_FACE ? FilterKind::FormFactorsOfFace : FilterKind::Radiosity;
}
}  // namespace

FilterRadiosityPlugin::FilterRadiosityPlugin() {
  typeList << FP_RADIOSITY << FP_FORM_FACTORS_OF_FACE;
  for (FilterIDType t : types()) actionList << new QAction(filterName(t), this);
}

QString FilterRadiosityPlugin::pluginName() const { return "FilterRadiosityGI"; }

QString FilterRadiosityPlugin::filterName(FilterIDType f) const {
  return QString::fromStdString(filterDesc(kindOf(f)).meshlabName);
}

QString FilterRadiosityPlugin::filterInfo(FilterIDType f) const {
  if (kindOf(f) == FilterKind::FormFactorsOfFace)
    return "The <b>form factors</b> F<sub>ij</sub> from the selected face i to every other face j: the fraction of "
           "the power leaving i (a Lambertian emitter) that arrives at j, visibility included. Written to face "
           "<b>quality</b> (and grey face colour, the selected face red); vertex quality gets the area-weighted mean "
           "of the incident faces. The log gives the row sum (1 in a closed room, less where light escapes) and the "
           "<b>reciprocity</b> error |A<sub>i</sub> F<sub>ij</sub> - A<sub>j</sub> F<sub>ji</sub>| / A<sub>i</sub> "
           "F<sub>ij</sub> over the strongest receivers. Compare the three methods (Monte Carlo rays, analytic "
           "point-to-polygon, hemicube) on the same face to see their errors and artefacts.";
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
         "sRGB(exposure &times; B). Every layer of the scene receives its result.<br>"
         "<b>Adaptive mesh refinement</b> (optional, 'refine'): solve, split the patches where the reflected "
         "radiosity jumps across an edge or differs from its corners' values, or where a shadow boundary crosses "
         "(the vertices see the lights differently), solve again, up to a depth or a patch budget. Red-green "
         "subdivision keeps the mesh free of T-junctions. The refined mesh replaces the layer's geometry; faces keep "
         "their colour, quality and selection, so the filter can be applied again.";
}

MeshFilterInterface::FilterClass FilterRadiosityPlugin::getClass(QAction*) {
  return FilterClass(MeshFilterInterface::VertexColoring | MeshFilterInterface::Quality);
}
MeshFilterInterface::FILTER_ARITY FilterRadiosityPlugin::filterArity(QAction*) const { return VARIABLE; }
int FilterRadiosityPlugin::getPreConditions(QAction*) const { return MeshModel::MM_NONE; }
int FilterRadiosityPlugin::postCondition(QAction* a) const {
  const int results = MeshModel::MM_VERTCOLOR | MeshModel::MM_VERTQUALITY | MeshModel::MM_FACECOLOR | MeshModel::MM_FACEQUALITY;
  // postCondition cannot see the parameters: GI: Radiosity may refine the
  // mesh (parameter 'refine'), so MeshLab must refresh geometry and topology.
  if (a && ID(a) == FP_RADIOSITY) return results | MeshModel::MM_GEOMETRY_AND_TOPOLOGY_CHANGE;
  return results;
}

void FilterRadiosityPlugin::initParameterSet(QAction* a, MeshDocument& md, RichParameterList& par) {
  ml::addParams(par, filterSpecs(kindOf(ID(a))), ml::documentDiagonal(md));
}

bool FilterRadiosityPlugin::applyFilter(QAction* a, MeshDocument& md, const RichParameterList& par, vcg::CallBackPos* cb) {
  auto logLine = [this](const std::string& s) { Log("%s", s.c_str()); };
  if (kindOf(ID(a)) == FilterKind::FormFactorsOfFace) {
    return ml::guarded(errorMessage, logLine, filterName(ID(a)), [&] {
      ml::PreparedRun run = ml::prepare(md, par, filterSpecs(FilterKind::FormFactorsOfFace), false);
      const Scene& s = run.bridge.scene;
      const uint32_t face = chosenFace(run.values.getInt("face_index"), run.bridge.attrs.faceSelected, s.faceCount());
      auto caster = makeEmbreeCaster(s);
      const FormFactorReport rep = formFactorsOfFace(s, *caster, formFactorSettings(run.values), face);
      const FormFactorOutput out = formFactorOutput(s, rep, face);
      ml::writeFaceResults(run.bridge, out.faceF, out.faceColor);
      ml::writeVertexResults(run.bridge, out.vertexF, {});
      logLine(out.summary);
    });
  }
  return ml::guarded(errorMessage, logLine, filterName(ID(a)), [&] {
    ml::PreparedRun run = ml::prepare(md, par, filterSpecs(FilterKind::Radiosity), true);
    const RadiosityOptions opt = RadiosityOptions::fromParams(run.values);
    RadiosityResult r;
    if (opt.refine) {
      // The refined mesh replaces the layers' geometry, then receives the results.
      AdaptiveRadiosity ar = solveRadiosityAdaptive(run.bridge.scene, opt, Progress(ml::progressFrom(cb)));
      r = std::move(ar.result);
      ml::replaceWithRefined(run.bridge, ar.mesh, r.Bvertex, r.B);
    } else {
      auto caster = makeEmbreeCaster(run.bridge.scene);
      r = solveRadiosity(run.bridge.scene, *caster, opt, Progress(ml::progressFrom(cb)));
    }
    ml::writeRadiosity(run, r.Bvertex, r.B, run.values.getBool("face_output"), r.stats);
    logLine(run.report.summary() + "; " + run.setupLog);
    logLine(r.stats.line("GI: Radiosity"));
  });
}

MESHLAB_PLUGIN_NAME_EXPORTER(FilterRadiosityPlugin)
