// MeshLab adapter for the engine's ambient occlusion, obscurance and sky
// lighting (gi/ambient.h). No algorithm code here.
#pragma once
#include <common/interfaces.h>

class FilterAmbientPlugin : public QObject, public MeshFilterInterface {
  Q_OBJECT
  MESHLAB_PLUGIN_IID_EXPORTER(MESH_FILTER_INTERFACE_IID)
  Q_INTERFACES(MeshFilterInterface)

 public:
  enum { FP_AMBIENT_OCCLUSION, FP_AMBIENT_OBSCURANCE, FP_SKY_LIGHTING };
  FilterAmbientPlugin();
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
