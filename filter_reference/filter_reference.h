// MeshLab adapter for the engine's path tracer (gi/pathtrace.h). No algorithm code here.
#pragma once
#include <common/interfaces.h>

class FilterReferencePlugin : public QObject, public MeshFilterInterface {
  Q_OBJECT
  MESHLAB_PLUGIN_IID_EXPORTER(MESH_FILTER_INTERFACE_IID)
  Q_INTERFACES(MeshFilterInterface)

 public:
  enum { FP_PATH_TRACED_REFERENCE };
  FilterReferencePlugin();
  QString pluginName() const override;
  QString filterName(FilterIDType filter) const override;
  QString filterInfo(FilterIDType filter) const override;
  FilterClass getClass(QAction* a) override;
  FILTER_ARITY filterArity(QAction*) const override;
  int getPreConditions(QAction*) const override;
  int postCondition(QAction*) const override;
  void initParameterSet(QAction* a, MeshDocument& md, RichParameterList& par) override;
  bool applyFilter(QAction* a, MeshDocument& md, const RichParameterList& par, vcg::CallBackPos* cb) override;
};
