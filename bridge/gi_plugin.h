// The MeshLab side of every GI plugin: one plugin offers the filters the
// engine's catalogue lists under its name (gi/filters.h), and each hook only
// reads or writes data: names and help from the catalogue, the dialog from the
// parameter table, the run through gi::runFilter, the result back into the
// layers. A concrete plugin is a QObject subclass naming its catalogue entry
// (Qt's moc needs one class declaration per plugin).
#pragma once
#include <string>

#include <common/interfaces.h>

namespace gi::ml {

class GiFilterPlugin : public MeshFilterInterface {
 public:
  explicit GiFilterPlugin(std::string plugin);
  QString pluginName() const override;
  QString filterName(FilterIDType f) const override;
  QString filterInfo(FilterIDType f) const override;
  FilterClass getClass(QAction* a) override;
  FILTER_ARITY filterArity(QAction*) const override;
  int getPreConditions(QAction*) const override;
  int postCondition(QAction* a) const override;
  void initParameterSet(QAction* a, MeshDocument& md, RichParameterList& par) override;
  bool applyFilter(QAction* a, MeshDocument& md, const RichParameterList& par, vcg::CallBackPos* cb) override;

 protected:
  // Fills typeList and actionList; the QObject subclass calls it with itself as the actions' parent.
  void createActions(QObject* owner);

 private:
  std::string plugin_;
};

}  // namespace gi::ml
