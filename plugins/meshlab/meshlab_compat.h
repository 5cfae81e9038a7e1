// SPDX-License-Identifier: GPL-3.0-or-later
// The MeshLab plugin interface the filter is built for, chosen by which headers are there:
//   2022.02 and later: common/plugins/interfaces/filter_plugin.h, class FilterPlugin
//     (const QAction*, initParameterList returning the list, applyFilter returning a map and
//     reporting errors by throwing MLException);
//   2020.09 (Debian 12): common/interfaces.h, class MeshFilterInterface (QAction*,
//     initParameterSet filling a list, applyFilter returning bool with errorMessage set).
// This header gives 2020.09 the later names the filter uses; filter_vstree.h declares the
// overrides of the interface it is built for, both forwarding to the same implementation.
#ifndef VSTREE_MESHLAB_COMPAT_H
#define VSTREE_MESHLAB_COMPAT_H

// VSTREE_MESHLAB_2020 is set by CMakeLists.txt from the headers found (not with __has_include:
// moc, which reads this header too, does not evaluate it).
#ifndef VSTREE_MESHLAB_2020
#error "VSTREE_MESHLAB_2020 must be defined (0 or 1); CMakeLists.txt sets it"
#endif
#if VSTREE_MESHLAB_2020
#include <common/interfaces.h>
#include <common/mlexception.h>
using FilterPlugin = MeshFilterInterface;
using ActionIDType = MeshFilterInterface::FilterIDType;
#define FILTER_PLUGIN_IID MESH_FILTER_INTERFACE_IID
#else
#include <common/plugins/interfaces/filter_plugin.h>
#endif

#endif
