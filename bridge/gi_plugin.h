// The MeshLab side of every GI plugin: one plugin offers the filters the
// engine's catalogue lists under its name (gi/filters.h), and each hook only
// reads or writes data: names and help from the catalogue, the dialog from the
// parameter table, the run through gi::runFilter, the result back into the
// layers. A concrete plugin is a QObject subclass naming its catalogue entry
// (Qt's moc needs one class declaration per plugin). The hooks are written once
// for MeshLab 2020.09 and 2025.07: ml_compat.h maps them onto each version's
// interface.
#pragma once
#include <string>

#include "ml_compat.h"

namespace gi::ml {

class GiFilterPlugin : public compat::FilterAdapter {
 public:
  explicit GiFilterPlugin(std::string plugin);
  QString pluginName() const override;
  QString filterName(compat::FilterId f) const override;
  QString filterInfo(compat::FilterId f) const override;

 protected:
  // Fills the plugin's filter and action lists; the QObject subclass calls it
  // with itself as the actions' parent.
  void createActions(QObject* owner);

  int giClass(compat::FilterId f) const override;
  int giPostCondition(compat::FilterId f) const override;
  void giParams(compat::FilterId f, MeshDocument& md, RichParameterList& par) override;
  QString giApply(compat::FilterId f, MeshDocument& md, const RichParameterList& par, vcg::CallBackPos* cb) override;

 private:
  std::string plugin_;
};

}  // namespace gi::ml
