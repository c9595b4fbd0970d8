#include "pqBlockForgeParametersWidget.h"

#include "vtkCommand.h"
#include "vtkEventQtSlotConnect.h"
#include "vtkSMProperty.h"
#include "vtkSMPropertyHelper.h"
#include "vtkSMProxy.h"

#include <QHeaderView>
#include <QLabel>
#include <QTableWidget>
#include <QVBoxLayout>

namespace
{
enum Column
{
  NameColumn,
  OverrideColumn,
  DefaultColumn,
  ValueColumn,
  UnitColumn,
  DescriptionColumn,
  ColumnCount
};
/// Strings per parameter in the information property: name, default, value, unit, text.
constexpr int InformationWidth = 5;
}

pqBlockForgeParametersWidget::pqBlockForgeParametersWidget(
  vtkSMProxy* proxy, vtkSMProperty* property, QWidget* parent)
  : Superclass(proxy, parent)
  , Table(new QTableWidget(this))
  , Status(new QLabel(this))
  , Connection(vtkEventQtSlotConnect::New())
{
  this->setShowLabel(true);
  this->setChangeAvailableAsChangeFinished(true);
  auto* layout = new QVBoxLayout(this);
  layout->setContentsMargins(0, 0, 0, 0);
  this->Table->setColumnCount(ColumnCount);
  this->Table->setHorizontalHeaderLabels(
    { tr("Parameter"), tr("Override"), tr("Default"), tr("Last Run"), tr("Unit"),
      tr("Description") });
  this->Table->horizontalHeader()->setStretchLastSection(true);
  this->Table->verticalHeader()->setVisible(false);
  this->Table->setSelectionMode(QAbstractItemView::SingleSelection);
  this->Table->setEditTriggers(QAbstractItemView::DoubleClicked |
    QAbstractItemView::EditKeyPressed | QAbstractItemView::AnyKeyPressed);
  this->Table->setToolTip(tr("Type an expression in the Override column to change a "
                             "parameter; clear it to use the template's default."));
  this->Table->setMinimumHeight(160);
  this->Status->setWordWrap(true);
  layout->addWidget(this->Table);
  layout->addWidget(this->Status);

  // Not `information_property`: ParaView would copy the information (five strings per
  // parameter) into the overrides.
  this->InformationProperty = proxy->GetProperty("TemplateParameters");
  // The information property is refreshed (modified) after the template was read.
  if (this->InformationProperty)
  {
    this->Connection->Connect(
      this->InformationProperty, vtkCommand::ModifiedEvent, this, SLOT(updateRows()));
  }
  QObject::connect(this->Table, &QTableWidget::cellChanged, this,
    &pqBlockForgeParametersWidget::cellChanged);
  this->addPropertyLink(this, "overrides", SIGNAL(overridesChanged()), property);
  this->updateRows();
}

pqBlockForgeParametersWidget::~pqBlockForgeParametersWidget()
{
  this->Connection->Disconnect();
  this->Connection->Delete();
}

QList<QVariant> pqBlockForgeParametersWidget::overrides() const
{
  QList<QVariant> pairs;
  for (int row = 0; row < this->Table->rowCount(); ++row)
  {
    const QTableWidgetItem* name = this->Table->item(row, NameColumn);
    const QTableWidgetItem* value = this->Table->item(row, OverrideColumn);
    const QString expression = value ? value->text().trimmed() : QString();
    if (name && !expression.isEmpty())
    {
      pairs << name->text() << expression;
    }
  }
  return pairs;
}

void pqBlockForgeParametersWidget::setOverrides(const QList<QVariant>& pairs)
{
  if (pairs == this->overrides())
  {
    return;
  }
  QList<QStringList> declared;
  for (int row = 0; row < this->Table->rowCount(); ++row)
  {
    if (this->Table->item(row, NameColumn)->data(Qt::UserRole).toBool())
    {
      QStringList entry;
      for (int column : { NameColumn, DefaultColumn, ValueColumn, UnitColumn, DescriptionColumn })
      {
        entry << this->Table->item(row, column)->text();
      }
      declared << entry;
    }
  }
  this->fillRows(declared, pairs);
}

void pqBlockForgeParametersWidget::updateRows()
{
  QList<QStringList> declared;
  if (this->InformationProperty)
  {
    vtkSMPropertyHelper helper(this->InformationProperty);
    const unsigned int count = helper.GetNumberOfElements();
    for (unsigned int n = 0; n + InformationWidth <= count; n += InformationWidth)
    {
      QStringList entry;
      for (int k = 0; k < InformationWidth; ++k)
      {
        const char* text = helper.GetAsString(n + k);
        entry << QString::fromUtf8(text ? text : "");
      }
      declared << entry;
    }
  }
  this->fillRows(declared, this->overrides());
}

void pqBlockForgeParametersWidget::fillRows(
  const QList<QStringList>& declared, const QList<QVariant>& pairs)
{
  this->Filling = true;
  QMap<QString, QString> byName;
  QStringList order;
  for (int n = 0; n + 1 < pairs.size(); n += 2)
  {
    byName[pairs[n].toString()] = pairs[n + 1].toString();
    order << pairs[n].toString();
  }
  this->Table->setRowCount(0);
  auto readOnly = [](const QString& text)
  {
    auto* item = new QTableWidgetItem(text);
    item->setFlags(item->flags() & ~Qt::ItemIsEditable);
    return item;
  };
  int row = 0;
  for (const QStringList& entry : declared)
  {
    this->Table->insertRow(row);
    auto* name = readOnly(entry[0]);
    name->setData(Qt::UserRole, true);
    name->setToolTip(entry[4]);
    this->Table->setItem(row, NameColumn, name);
    this->Table->setItem(row, OverrideColumn, new QTableWidgetItem(byName.value(entry[0])));
    this->Table->setItem(row, DefaultColumn, readOnly(entry[1]));
    this->Table->setItem(row, ValueColumn, readOnly(entry[2]));
    this->Table->setItem(row, UnitColumn, readOnly(entry[3]));
    this->Table->setItem(row, DescriptionColumn, readOnly(entry[4]));
    byName.remove(entry[0]);
    ++row;
  }
  // Overrides of names the template does not declare: kept and marked.
  for (const QString& unknown : order)
  {
    if (!byName.contains(unknown))
    {
      continue;
    }
    this->Table->insertRow(row);
    auto* name = readOnly(unknown);
    name->setData(Qt::UserRole, false);
    name->setForeground(Qt::red);
    this->Table->setItem(row, NameColumn, name);
    this->Table->setItem(row, OverrideColumn, new QTableWidgetItem(byName.value(unknown)));
    for (int column : { DefaultColumn, ValueColumn, UnitColumn })
    {
      this->Table->setItem(row, column, readOnly(QString()));
    }
    this->Table->setItem(
      row, DescriptionColumn, readOnly(tr("not a parameter of this template")));
    ++row;
  }
  this->Table->resizeColumnsToContents();
  this->Status->setText(declared.isEmpty()
      ? tr("The template's parameters are listed here once it has been read (Apply).")
      : tr("%1 parameters; type a value or expression in Override, clear it for the default.")
          .arg(declared.size()));
  this->Filling = false;
}

void pqBlockForgeParametersWidget::cellChanged(int, int column)
{
  if (!this->Filling && column == OverrideColumn)
  {
    Q_EMIT this->overridesChanged();
  }
}
