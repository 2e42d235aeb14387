// The one place where the MeshLab versions we build for differ. The bridge and
// the plugins are written once against what this header offers; CMake picks the
// version (GI_MESHLAB_TARGET, see cmake/MeshLabSDK.cmake), which defines
// GI_MESHLAB_2025 for MeshLab 2025.07 and nothing for 2020.09.
//
// What changed between the two (MeshLab's own sources, src/common):
//  - the filter interface: MeshFilterInterface (2020.09, common/interfaces.h) became
//    FilterPlugin (2025.07, common/plugins/interfaces/filter_plugin.h) with a new IID;
//    the hooks take const QAction*, initParameterSet fills a list while
//    initParameterList returns one (and sees the document const), applyFilter
//    returns a map of results and reports failure by throwing MLException instead
//    of returning false with errorMessage set; Log() became log();
//  - parameters: RichAbsPerc became RichPercentage, RichPoint3f became RichPosition
//    or RichDirection (of Point3m);
//  - the document: MeshDocument::meshList (a QList of pointers) became private,
//    iterated by meshIterator(); Plane (a raster layer's image) became RasterPlane;
//  - a 2025.07 plugin must report the MeshLab version it was built for
//    (MESHLAB_PLUGIN_IID_EXPORTER adds getMLVersion); MeshLab loads only plugins of
//    its own version and scalar type.
#pragma once
#include <QAction>
#include <QObject>
#include <QString>
#include <string>
#include <vector>

#ifdef GI_MESHLAB_2025
#include <common/mlexception.h>
#include <common/plugins/interfaces/filter_plugin.h>
#define GI_FILTER_INTERFACE FilterPlugin
#define GI_FILTER_IID FILTER_PLUGIN_IID
#else
#include <common/interfaces.h>
#define GI_FILTER_INTERFACE MeshFilterInterface
#define GI_FILTER_IID MESH_FILTER_INTERFACE_IID
#endif

// In the body of each plugin class, after Q_OBJECT (moc reads it): the Qt plugin
// metadata and the MeshLab interface the class implements.
#define GI_MESHLAB_FILTER_PLUGIN                \
  MESHLAB_PLUGIN_IID_EXPORTER(GI_FILTER_IID)    \
  Q_INTERFACES(GI_FILTER_INTERFACE)

namespace gi::ml::compat {

using FilterBase = GI_FILTER_INTERFACE;
using FilterId = int;  // FilterIDType (2020.09) and ActionIDType (2025.07) are both int
#ifdef GI_MESHLAB_2025
using ImagePlane = RasterPlane;
#else
using ImagePlane = Plane;
#endif

// The document's layers, in layer-dialog order.
std::vector<MeshModel*> meshes(MeshDocument& md);
// A new, empty mesh layer named `label` (not made current).
MeshModel* addMeshLayer(MeshDocument& md, const QString& label);

// Dialog parameters whose class changed: a distance with its percentage of the
// diagonal, and a point or a direction.
void addDistance(RichParameterList& out, const QString& name, float def, float max, const QString& label,
                 const QString& help);
void addPoint(RichParameterList& out, const QString& name, const Point3m& def, bool direction, const QString& label,
              const QString& help);

// MeshLab's hooks, implemented once in MeshLab-neutral terms by GiFilterPlugin;
// FilterAdapter overrides each version's virtual functions with them.
class FilterAdapter : public FilterBase {
 public:
#ifdef GI_MESHLAB_2025
  using FilterBase::filterInfo;
  using FilterBase::filterName;
  using FilterBase::initParameterList;
  FilterClass getClass(const QAction* a) const override { return FilterClass(giClass(ID(a))); }
  FilterArity filterArity(const QAction*) const override { return VARIABLE; }
  int getPreConditions(const QAction*) const override { return MeshModel::MM_NONE; }
  int postCondition(const QAction* a) const override { return giPostCondition(ID(a)); }
  // 2025.07 hands the document over const; the parameters only read it (the diagonal).
  RichParameterList initParameterList(const QAction* a, const MeshDocument& md) override {
    RichParameterList par;
    giParams(ID(a), const_cast<MeshDocument&>(md), par);
    return par;
  }
  std::map<std::string, QVariant> applyFilter(const QAction* a, const RichParameterList& par, MeshDocument& md,
                                              unsigned int& /*postConditionMask: postCondition() says it*/,
                                              vcg::CallBackPos* cb) override {
    const QString why = giApply(ID(a), md, par, cb);
    if (!why.isEmpty()) throw MLException(why);  // MeshLab shows it and logs "<filter> failed: ..."
    return {};
  }
#else
  FilterClass getClass(QAction* a) override { return FilterClass(giClass(ID(a))); }
  FILTER_ARITY filterArity(QAction*) const override { return VARIABLE; }
  int getPreConditions(QAction*) const override { return MeshModel::MM_NONE; }
  int postCondition(QAction* a) const override { return giPostCondition(ID(a)); }
  void initParameterSet(QAction* a, MeshDocument& md, RichParameterList& par) override { giParams(ID(a), md, par); }
  bool applyFilter(QAction* a, MeshDocument& md, const RichParameterList& par, vcg::CallBackPos* cb) override {
    errorMessage = giApply(ID(a), md, par, cb);
    return errorMessage.isEmpty();
  }
#endif

 protected:
  // FilterClass bits (the same values in both versions).
  virtual int giClass(FilterId f) const = 0;
  virtual int giPostCondition(FilterId f) const = 0;
  virtual void giParams(FilterId f, MeshDocument& md, RichParameterList& par) = 0;
  // Runs the filter: an empty string on success, else why it failed (the mesh unchanged).
  virtual QString giApply(FilterId f, MeshDocument& md, const RichParameterList& par, vcg::CallBackPos* cb) = 0;

  // One line in MeshLab's log (shown by the GUI, printed by meshlabserver).
  void giLog(const std::string& line);
  // Offers filter f as a menu action owned by `owner` (the plugin's QObject).
  void giAddAction(FilterId f, const QString& name, QObject* owner);
};

}  // namespace gi::ml::compat
