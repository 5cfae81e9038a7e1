// SPDX-License-Identifier: GPL-3.0-or-later
// vstree MeshLab filter plugin: VS-Tree clustering simplification, surface reconstruction
// and cluster colouring through the vstree C API. Copyright the vstree authors.
// This program is free software: you can redistribute it and/or modify it under the terms
// of the GNU General Public License as published by the Free Software Foundation, either
// version 3 of the License, or (at your option) any later version.
#ifndef VSTREE_MESHLAB_FILTER_VSTREE_H
#define VSTREE_MESHLAB_FILTER_VSTREE_H

#include <common/plugins/interfaces/filter_plugin.h>

class FilterVstreePlugin : public QObject, public FilterPlugin
{
	Q_OBJECT
	MESHLAB_PLUGIN_IID_EXPORTER(FILTER_PLUGIN_IID)
	Q_INTERFACES(FilterPlugin)

public:
	enum { FP_SIMPLIFY, FP_RECONSTRUCT, FP_COLOUR };

	FilterVstreePlugin();

	QString pluginName() const override;
	QString vendor() const override;
	QString filterName(ActionIDType filter) const override;
	QString pythonFilterName(ActionIDType filter) const override;
	QString filterInfo(ActionIDType filter) const override;
	FilterClass getClass(const QAction* a) const override;
	FilterArity filterArity(const QAction* a) const override;
	int getPreConditions(const QAction* a) const override;
	int postCondition(const QAction* a) const override;
	RichParameterList initParameterList(const QAction* a, const MeshModel& m) override;
	std::map<std::string, QVariant> applyFilter(
		const QAction*           action,
		const RichParameterList& params,
		MeshDocument&            md,
		unsigned int&            postConditionMask,
		vcg::CallBackPos*        cb) override;
};

#endif
