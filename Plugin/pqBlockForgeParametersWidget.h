/**
 * @class   pqBlockForgeParametersWidget
 * @brief   Panel widget of BlockTemplateSource's and BlockTemplate's Parameters: a table
 *          of the template's parameters (name, override, default, value in the last run,
 *          unit, description) in which an override is typed in place.
 *
 * The rows come from the proxy's information property TemplateParameters (filled when
 * the template is read); the
 * Override column edits the Parameters property (name/expression pairs) like any other
 * property widget: the change waits for Apply. Overrides of names the template does not
 * declare stay in the table, marked, so that a typo is visible rather than lost (the
 * template engine reports it as an error).
 *
 * Selected by `panel_widget="blockforge_template_parameters"` in the proxies' XML.
 */
#ifndef pqBlockForgeParametersWidget_h
#define pqBlockForgeParametersWidget_h

#include "pqPropertyWidget.h"

#include <QList>
#include <QVariant>

class QLabel;
class QTableWidget;
class vtkEventQtSlotConnect;
class vtkSMProperty;

class pqBlockForgeParametersWidget : public pqPropertyWidget
{
  Q_OBJECT
  Q_PROPERTY(QList<QVariant> overrides READ overrides WRITE setOverrides)
  typedef pqPropertyWidget Superclass;

public:
  pqBlockForgeParametersWidget(
    vtkSMProxy* proxy, vtkSMProperty* property, QWidget* parent = nullptr);
  ~pqBlockForgeParametersWidget() override;

  /// Name/expression pairs of the non-empty overrides, in table order.
  QList<QVariant> overrides() const;
  /// Shows these name/expression pairs in the Override column.
  void setOverrides(const QList<QVariant>& pairs);

Q_SIGNALS:
  void overridesChanged();

private Q_SLOTS:
  /// Rebuilds the rows from the information property, keeping the overrides.
  void updateRows();
  void cellChanged(int row, int column);

private:
  void fillRows(const QList<QStringList>& declared, const QList<QVariant>& pairs);

  QTableWidget* Table;
  QLabel* Status;
  vtkSMProperty* InformationProperty = nullptr;
  vtkEventQtSlotConnect* Connection;
  bool Filling = false;
};

#endif
