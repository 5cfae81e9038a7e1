// SPDX-License-Identifier: GPL-3.0-or-later
// vstree MeshLab filter plugin: VS-Tree clustering simplification, surface reconstruction
// and cluster colouring through the vstree C API. Copyright the vstree authors.
// This program is free software: you can redistribute it and/or modify it under the terms
// of the GNU General Public License as published by the Free Software Foundation, either
// version 3 of the License, or (at your option) any later version.
#ifndef VSTREE_MESHLAB_FILTER_VSTREE_H
#define VSTREE_MESHLAB_FILTER_VSTREE_H

#include "meshlab_compat.h"

#include <map>
#include <string>

class FilterVstreePlugin : public QObject, public FilterPlugin
{
	Q_OBJECT
	MESHLAB_PLUGIN_IID_EXPORTER(FILTER_PLUGIN_IID)
#if VSTREE_MESHLAB_2020
	Q_INTERFACES(MeshFilterInterface) // moc knows interfaces by their declared name, not an alias
#else
	Q_INTERFACES(FilterPlugin)
#endif

public:
	enum { FP_SIMPLIFY, FP_RECONSTRUCT, FP_COLOUR };

	FilterVstreePlugin();

	QString pluginName() const override;
	QString filterName(ActionIDType filter) const override;
	QString filterInfo(ActionIDType filter) const override;
#if VSTREE_MESHLAB_2020
	FilterClass getClass(QAction* a) override;
	FILTER_ARITY filterArity(QAction* a) const override;
	int getPreConditions(QAction* a) const override;
	int postCondition(QAction* a) const override;
	void initParameterSet(QAction* a, MeshModel& m, RichParameterList& params) override;
	bool applyFilter(QAction* action, MeshDocument& md, const RichParameterList& params, vcg::CallBackPos* cb) override;
#else
	QString vendor() const override;
	QString pythonFilterName(ActionIDType filter) const override;
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
#endif

private:
	// The implementation, shared by both interfaces.
	FilterClass                     filterClass(ActionIDType f) const;
	int                             postConditionOf(ActionIDType f) const;
	RichParameterList               parameters(ActionIDType f, const MeshModel& m) const;
	std::map<std::string, QVariant> apply(
		ActionIDType f, const RichParameterList& params, MeshDocument& md, vcg::CallBackPos* cb);
	template <typename... Ts>
	void logf(const char* format, Ts&&... ts)
	{
#if VSTREE_MESHLAB_2020
		Log(format, std::forward<Ts>(ts)...);
#else
		log(format, std::forward<Ts>(ts)...);
#endif
	}
};

#endif
