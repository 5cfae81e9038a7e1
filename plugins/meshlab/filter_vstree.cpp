// SPDX-License-Identifier: GPL-3.0-or-later
// vstree MeshLab filter plugin: VS-Tree clustering simplification, surface reconstruction
// and cluster colouring through the vstree C API. Copyright the vstree authors.
// This program is free software: you can redistribute it and/or modify it under the terms
// of the GNU General Public License as published by the Free Software Foundation, either
// version 3 of the License, or (at your option) any later version.
#include "filter_vstree.h"

#include <vcg/complex/algorithms/update/bounding.h>
#include <vcg/complex/algorithms/update/normal.h>

#include <vstree.h>

// MeshLab 2025 renamed RichAbsPerc (a length given as an absolute value or a percentage of the
// bounding-box diagonal) to RichPercentage.
#if __has_include(<common/parameters/rich_parameters.h>)
using DistanceParam = RichPercentage;
#else
using DistanceParam = RichAbsPerc;
#endif

#include <cmath>
#include <cstdint>
// pymeshlab returns only int, double, bool and string outputs: counts go out as int.
#include <vector>

namespace {

const QStringList kLabelKinds{"Cluster", "T-node"};

// The library's parameter table (vstree_param_get()) gives every parameter's label, default,
// range, unit, description and choices: the dialogs are built from it, so they say what the
// library does. The filters' parameter names stay MeshLab's (pymeshlab scripts use them).

// The library's parameter `name` of `call` (VSTREE_CALL_*).
const vstree_param_info& param(int32_t call, const char* name)
{
	const int32_t index = vstree_param_find(call, name);
	const vstree_param_info* p = index < 0 ? nullptr : vstree_param_get(uint32_t(index));
	if (p == nullptr)
		throw MLException(QString("vstree: the library has no parameter '%1'").arg(name));
	return *p;
}

// A parameter's description with its range and unit, for the dialog's tooltip.
QString describe(const vstree_param_info& p)
{
	QString text = QString::fromUtf8(p.help);
	if (p.kind == VSTREE_PARAM_REAL || p.kind == VSTREE_PARAM_INTEGER) {
		const QString high = std::isinf(p.max) ? QString::fromUtf8("\u221e") : QString::number(p.max);
		text += QString(" Range %1%2, %3%4").arg(p.min_open ? "(" : "[").arg(p.min).arg(high).arg(p.max_open || std::isinf(p.max) ? ")" : "]");
		if (*p.unit != '\0')
			text += QString(", in %1").arg(QString::fromUtf8(p.unit));
		text += ".";
	}
	return text;
}

// The choices' labels, in the table's order (which is their values' order).
QStringList choiceLabels(int32_t call, const char* name)
{
	const int32_t index = vstree_param_find(call, name);
	const vstree_param_info& p = param(call, name);
	QStringList labels;
	for (uint32_t k = 0; k < p.choice_count; ++k)
		labels << QString::fromUtf8(vstree_param_choice_get(uint32_t(index), k)->label);
	return labels;
}

// The value of the choice a dialog's enum parameter `field` holds, for the library's `name`.
int32_t choiceValue(const RichParameterList& par, const char* field, int32_t call, const char* name)
{
	const int32_t index = vstree_param_find(call, name);
	const vstree_param_choice* c = vstree_param_choice_get(uint32_t(index), uint32_t(par.getEnum(field)));
	if (c == nullptr)
		throw MLException(QString("vstree: '%1' holds no choice of the library's '%2'").arg(field).arg(name));
	return c->value;
}

RichEnum enumParam(const char* field, int32_t call, const char* name)
{
	const vstree_param_info& p = param(call, name);
	return RichEnum(field, int(p.default_value), choiceLabels(call, name), QString::fromUtf8(p.label), describe(p));
}

RichFloat floatParam(const char* field, int32_t call, const char* name)
{
	const vstree_param_info& p = param(call, name);
	return RichFloat(field, Scalarm(p.default_value), QString::fromUtf8(p.label), describe(p));
}

RichInt intParam(const char* field, int32_t call, const char* name)
{
	const vstree_param_info& p = param(call, name);
	return RichInt(field, int(p.default_value), QString::fromUtf8(p.label), describe(p));
}

// A vstree status other than OK becomes an MLException carrying the C API's own message;
// pymeshlab turns it into pymeshlab.PyMeshLabException.
void check(vstree_status st, const char* what)
{
	if (st == VSTREE_STATUS_OK)
		return;
	const QString detail = QString::fromUtf8(vstree_last_error_message());
	throw MLException(QString("vstree %1 failed (%2): %3")
						  .arg(what)
						  .arg(QString::fromUtf8(vstree_status_str(st)))
						  .arg(detail));
}

struct Progress
{
	vcg::CallBackPos* cb;
	int               lastPercent = -1;
};

int32_t progressTrampoline(void* user, float fraction, const char* stage)
{
	auto* p = static_cast<Progress*>(user);
	if (p->cb == nullptr)
		return 1;
	int percent = int(std::lround(double(fraction) * 100.0));
	if (percent != p->lastPercent) {
		p->lastPercent = percent;
		p->cb(percent, stage != nullptr ? stage : "");
	}
	return 1; // never cancel: MeshLab's callback result is not a cancel request
}

// Live (non-deleted) vertices and faces of a CMeshO as flat arrays.
struct Arrays
{
	std::vector<float>    pos;
	std::vector<float>    nrm;
	std::vector<uint32_t> tri;
	std::vector<int>      vertIndex; // compact index -> index in m.vert
	size_t                zeroNormals = 0;
};

Arrays toArrays(const CMeshO& m)
{
	Arrays a;
	std::vector<uint32_t> remap(m.vert.size(), UINT32_MAX);
	for (size_t i = 0; i < m.vert.size(); ++i) {
		const auto& v = m.vert[i];
		if (v.IsD())
			continue;
		remap[i] = uint32_t(a.vertIndex.size());
		a.vertIndex.push_back(int(i));
		for (int k = 0; k < 3; ++k) {
			a.pos.push_back(float(v.cP()[k]));
			a.nrm.push_back(float(v.cN()[k]));
		}
		if (v.cN().SquaredNorm() == 0 || !std::isfinite(double(v.cN().SquaredNorm())))
			++a.zeroNormals;
	}
	for (const auto& f : m.face) {
		if (f.IsD())
			continue;
		for (int k = 0; k < 3; ++k)
			a.tri.push_back(remap[vcg::tri::Index(m, f.cV(k))]);
	}
	return a;
}

struct MeshHandle
{
	vstree_mesh* p = nullptr;
	~MeshHandle() { vstree_mesh_free(p); }
};

// Copy a vstree mesh into an (empty) CMeshO.
void fromVstree(const vstree_mesh* vm, CMeshO& out)
{
	const size_t nv = vstree_mesh_vertex_count(vm);
	const size_t nt = vstree_mesh_triangle_count(vm);
	std::vector<float>    pos(nv * 3), nrm;
	std::vector<uint32_t> tri(nt * 3);
	check(vstree_mesh_copy_positions(vm, pos.data(), pos.size()), "copy positions");
	check(vstree_mesh_copy_triangles(vm, nt ? tri.data() : nullptr, tri.size()), "copy triangles");
	const bool hasN = vstree_mesh_has_normals(vm) == 1;
	if (hasN) {
		nrm.resize(nv * 3);
		check(vstree_mesh_copy_normals(vm, nrm.data(), nrm.size()), "copy normals");
	}
	out.Clear();
	auto vi = vcg::tri::Allocator<CMeshO>::AddVertices(out, nv);
	for (size_t i = 0; i < nv; ++i, ++vi) {
		vi->P() = Point3m(pos[3 * i], pos[3 * i + 1], pos[3 * i + 2]);
		if (hasN)
			vi->N() = Point3m(nrm[3 * i], nrm[3 * i + 1], nrm[3 * i + 2]);
	}
	if (nt > 0) {
		auto fi = vcg::tri::Allocator<CMeshO>::AddFaces(out, nt);
		for (size_t t = 0; t < nt; ++t, ++fi)
			for (int k = 0; k < 3; ++k)
				fi->V(k) = &out.vert[tri[3 * t + k]];
		vcg::tri::UpdateNormal<CMeshO>::PerFaceNormalized(out);
		if (!hasN)
			vcg::tri::UpdateNormal<CMeshO>::PerVertexNormalizedPerFace(out);
	}
	vcg::tri::UpdateBounding<CMeshO>::Box(out);
}

// The vstree input mesh of a MeshLab layer. Triangle meshes go without normals (vstree takes
// area-weighted ones from the triangles); point clouds go with their normals when every point
// has one, else without (simplification then reports the missing normals).
void makeInput(const Arrays& a, bool withNormals, MeshHandle& h)
{
	if (a.vertIndex.empty())
		throw MLException("vstree: the current layer has no vertices");
	const float* n = withNormals ? a.nrm.data() : nullptr;
	check(vstree_mesh_create(a.pos.data(), a.vertIndex.size(), n, a.tri.empty() ? nullptr : a.tri.data(),
			  a.tri.size() / 3, &h.p),
		"mesh_create");
}

// The L2 bound from the "distance" parameter when it is set: every sample's tangent plane then
// passes within that distance of its cluster's point, since the bound e on the summed squared
// plane distances over diag^2 gives each one at most sqrt(e) * diag. Otherwise "error" as given.
double l2Bound(const RichParameterList& par, double diagonal)
{
	const double bound = vstree_l2_error_for_distance(double(par.getAbsPerc("distance")), diagonal);
	return bound > 0 ? bound : double(par.getFloat("error"));
}

void addDistanceParam(RichParameterList& pl, double diagonal)
{
	pl.addParam(DistanceParam("distance", 0, 0, Scalarm(diagonal), "Max plane distance",
		"The error bound as a length (an absolute value, or a percentage of the bounding-box "
		"diagonal): every sample's tangent plane passes within this distance of its cluster's "
		"point. When set (> 0) it replaces 'Error bound' with (distance / diagonal)^2; L2 metric "
		"only. 0 uses 'Error bound'."));
}

vstree_simplify_params simplifyParams(const RichParameterList& par, double diagonal)
{
	vstree_simplify_params p = vstree_simplify_params_default();
	p.tree_kind = choiceValue(par, "tree_kind", VSTREE_CALL_SIMPLIFY, "tree_kind");
	p.metric = choiceValue(par, "metric", VSTREE_CALL_SIMPLIFY, "metric");
	p.sampling = choiceValue(par, "sampling", VSTREE_CALL_SIMPLIFY, "sampling");
	p.error    = double(par.getFloat("error"));
	if (par.getAbsPerc("distance") > 0) {
		if (p.metric != VSTREE_METRIC_L2)
			throw MLException("vstree: 'Max plane distance' applies to the L2 metric only; set it to 0 or choose L2");
		p.error = l2Bound(par, diagonal);
	}
	p.d_a      = float(par.getFloat("d_a"));
	p.d_d      = float(par.getFloat("d_d"));
	p.max_depth = uint32_t(std::max(0, par.getInt("max_depth")));
	return p;
}

// The size and topology parameters of the simplification filter (like MeshLab's quadric edge
// collapse: a face count, or a fraction of the input's faces that overrides it).
void addSizeParams(RichParameterList& pl)
{
	pl.addParam(intParam("target_faces", VSTREE_CALL_SIMPLIFY, "target_faces"));
	pl.addParam(RichFloat("target_perc", 0, "Percentage reduction (0..1)",
		"If non zero, the wanted size as a fraction of the input's faces (0.1 keeps 10%); it "
		"overrides the target number of faces."));
	pl.addParam(enumParam("keep_topology", VSTREE_CALL_SIMPLIFY, "keep_topology"));
}

// Sets the size and topology fields from the filter's parameters, for an input of `faces`
// triangles.
void setSize(const RichParameterList& par, size_t faces, vstree_simplify_params& p)
{
	const double perc = double(par.getFloat("target_perc"));
	const int target = par.getInt("target_faces");
	if (!(perc >= 0 && perc <= 1))
		throw MLException(QString("vstree: 'Percentage reduction' is %1: it must be in (0, 1], or 0 to use the "
								  "target number of faces").arg(perc));
	if (target < 0)
		throw MLException(QString("vstree: 'Target number of faces' is %1: it must be at least 1, or 0 to use "
								  "the error bound").arg(target));
	p.target_faces = uint32_t(target);
	if (perc > 0)
		check(vstree_faces_for_ratio(perc, faces, &p.target_faces), "faces_for_ratio");
	p.keep_topology = choiceValue(par, "keep_topology", VSTREE_CALL_SIMPLIFY, "keep_topology");
}

// The tree's parameters, from the library's table.
void addTreeParams(RichParameterList& pl, double diagonal)
{
	pl.addParam(floatParam("error", VSTREE_CALL_SIMPLIFY, "error"));
	addDistanceParam(pl, diagonal);
	pl.addParam(enumParam("tree_kind", VSTREE_CALL_SIMPLIFY, "tree_kind"));
	pl.addParam(enumParam("metric", VSTREE_CALL_SIMPLIFY, "metric"));
	pl.addParam(floatParam("d_a", VSTREE_CALL_SIMPLIFY, "d_a"));
	pl.addParam(floatParam("d_d", VSTREE_CALL_SIMPLIFY, "d_d"));
	pl.addParam(enumParam("sampling", VSTREE_CALL_SIMPLIFY, "sampling"));
	pl.addParam(intParam("max_depth", VSTREE_CALL_SIMPLIFY, "max_depth"));
}

uint32_t hashColour(uint32_t x)
{
	x ^= x >> 16; x *= 0x7feb352dU; x ^= x >> 15; x *= 0x846ca68bU; x ^= x >> 16;
	return x;
}

} // namespace

FilterVstreePlugin::FilterVstreePlugin()
{
	typeList = {FP_SIMPLIFY, FP_RECONSTRUCT, FP_COLOUR};
	for (ActionIDType tt : types())
		actionList.push_back(new QAction(filterName(tt), this));
}

QString FilterVstreePlugin::pluginName() const { return "FilterVstree"; }

QString FilterVstreePlugin::filterName(ActionIDType f) const
{
	switch (f) {
	case FP_SIMPLIFY: return "VS-Tree Clustering Simplification";
	case FP_RECONSTRUCT: return "VS-Tree Surface Reconstruction";
	case FP_COLOUR: return "VS-Tree Cluster Colouring";
	default: return QString();
	}
}

QString FilterVstreePlugin::filterInfo(ActionIDType f) const
{
	const QString ver = QString(" (libvstree %1)").arg(QString::fromUtf8(vstree_version()));
	switch (f) {
	case FP_SIMPLIFY:
		return "Clustering simplification with a Volume-Surface Tree (Boubekeur et al. 2006): every "
			   "cluster of the tree becomes one vertex. The result is a <b>new layer</b>; the source "
			   "layer is not changed. Works on triangle meshes and on point clouds with normals." + ver;
	case FP_RECONSTRUCT:
		return "Surface reconstruction from a point set with a VS-Tree: a coarse closed base mesh from "
			   "the T-nodes, refined by the quadtrees. Normals are estimated where missing (unless "
			   "disabled). The result is a <b>new layer</b>." + ver;
	case FP_COLOUR:
		return "Colours the vertices of the current layer by the VS-Tree cluster (or T-node) they "
			   "belong to, one hash colour per label; unlabelled vertices become grey." + ver;
	default: return QString();
	}
}

FilterPlugin::FilterClass FilterVstreePlugin::filterClass(ActionIDType f) const
{
	switch (f) {
	case FP_SIMPLIFY: return FilterPlugin::Remeshing;
	case FP_RECONSTRUCT: return FilterClass(FilterPlugin::PointSet | FilterPlugin::Remeshing);
	case FP_COLOUR: return FilterPlugin::VertexColoring;
#if VSTREE_MESHLAB_2020
	default: return FilterPlugin::Generic; // renamed Other in 2022.02
#else
	default: return FilterPlugin::Other;
#endif
	}
}

int FilterVstreePlugin::postConditionOf(ActionIDType f) const
{
	switch (f) {
	case FP_COLOUR: return MeshModel::MM_VERTCOLOR;
	default: return MeshModel::MM_NONE; // new layer, source untouched
	}
}

RichParameterList FilterVstreePlugin::parameters(ActionIDType f, const MeshModel& m) const
{
	RichParameterList pl;
	const double diagonal = double(m.cm.bbox.Diag());
	switch (f) {
	case FP_SIMPLIFY:
		addSizeParams(pl);
		addTreeParams(pl, diagonal);
		break;
	case FP_COLOUR:
		addTreeParams(pl, diagonal);
		pl.addParam(RichEnum("label", 0, kLabelKinds, "Colour by",
			"Cluster: one colour per cluster (leaf). T-node: one colour per T-node of the T-layer."));
		break;
	case FP_RECONSTRUCT: {
		pl.addParam(floatParam("error", VSTREE_CALL_RECONSTRUCT, "error"));
		addDistanceParam(pl, diagonal);
		pl.addParam(intParam("levels", VSTREE_CALL_RECONSTRUCT, "max_levels"));
		pl.addParam(enumParam("surface", VSTREE_CALL_RECONSTRUCT, "closure"));
		pl.addParam(floatParam("trim", VSTREE_CALL_RECONSTRUCT, "trim"));
		pl.addParam(RichBool("estimate_normals", true, "Estimate normals",
			"Estimate (and orient outward) the normals the point set lacks. When off, the point set "
			"must have normals."));
		break;
	}
	default: break;
	}
	return pl;
}

std::map<std::string, QVariant> FilterVstreePlugin::apply(
	ActionIDType filter, const RichParameterList& par, MeshDocument& md, vcg::CallBackPos* cb)
{
	std::map<std::string, QVariant> out;
	MeshModel* src = md.mm();
	if (src == nullptr)
		throw MLException("vstree: no current mesh");
	Progress prog{cb};
	const Arrays a = toArrays(src->cm);
	const bool   isCloud = a.tri.empty();
	// Only point clouds pass normals; all of them must be non-zero.
	const bool passNormals = isCloud && a.zeroNormals == 0;

	switch (filter) {
	case FP_SIMPLIFY: {
		MeshHandle in;
		makeInput(a, passNormals, in);
		vstree_simplify_params p = simplifyParams(par, double(src->cm.bbox.Diag()));
		setSize(par, a.tri.size() / 3, p);
		vstree_simplify_result* res = nullptr;
		check(vstree_simplify(in.p, &p, progressTrampoline, &prog, &res), "simplify");
		struct Free { vstree_simplify_result* r; ~Free() { vstree_simplify_result_free(r); } } guard{res};
		const vstree_simplify_stats* s = vstree_simplify_result_get_stats(res);
		MeshModel* dst = md.addNewMesh("", src->label() + " (vstree)", true);
		fromVstree(vstree_simplify_result_get_mesh(res), dst->cm);
		logf("VS-Tree simplification: %llu -> %llu vertices, %llu -> %llu triangles, %llu clusters "
			"(%llu V, %llu T, %llu S nodes), depth %u, %.3f s",
			(unsigned long long)s->input_vertices, (unsigned long long)s->output_vertices,
			(unsigned long long)s->input_triangles, (unsigned long long)s->output_triangles,
			(unsigned long long)s->clusters, (unsigned long long)s->v_nodes,
			(unsigned long long)s->t_nodes, (unsigned long long)s->s_nodes, s->max_depth,
			s->seconds_total);
		logf("topology %s", s->kept_topology ? "kept" : "not kept (plain clustering)");
		if (const char* why = vstree_simplify_size_missed(s))
			logf("%llu triangles instead of the %llu asked for: %s", (unsigned long long)s->output_triangles,
				(unsigned long long)s->target_faces, why);
		out["output_vertices"] = QVariant(int(s->output_vertices));
		out["output_triangles"] = QVariant(int(s->output_triangles));
		out["clusters"] = QVariant(int(s->clusters));
		out["kept_topology"] = QVariant(int(s->kept_topology));
		out["t_nodes"] = QVariant(int(s->t_nodes));
		out["new_mesh_id"] = QVariant(dst->id());
		break;
	}
	case FP_RECONSTRUCT: {
		const bool estimate = par.getBool("estimate_normals");
		if (!estimate && a.zeroNormals > 0)
			throw MLException(QString("vstree: the point set has no normals (%1 of %2 points have a "
									  "zero normal) and 'Estimate normals' is off; turn it on or "
									  "compute normals first")
								  .arg(qulonglong(a.zeroNormals))
								  .arg(qulonglong(a.vertIndex.size())));
		MeshHandle in;
		// Triangles are ignored by reconstruction; normals go when every point has one.
		Arrays pts = a;
		pts.tri.clear();
		makeInput(pts, a.zeroNormals == 0, in);
		vstree_reconstruct_params p = vstree_reconstruct_params_default();
		p.error = l2Bound(par, double(src->cm.bbox.Diag()));
		const int levels = par.getInt("levels");
		const vstree_param_info& range = param(VSTREE_CALL_RECONSTRUCT, "max_levels");
		if (levels < range.min || levels > range.max)
			throw MLException(QString("vstree: levels must be in [%1, %2], got %3").arg(range.min).arg(range.max).arg(levels));
		p.max_levels = uint32_t(levels);
		p.closure = choiceValue(par, "surface", VSTREE_CALL_RECONSTRUCT, "closure");
		p.trim = float(par.getFloat("trim"));
		vstree_reconstruct_result* res = nullptr;
		check(vstree_reconstruct(in.p, &p, progressTrampoline, &prog, &res), "reconstruct");
		struct Free { vstree_reconstruct_result* r; ~Free() { vstree_reconstruct_result_free(r); } } guard{res};
		const vstree_reconstruct_stats* s = vstree_reconstruct_result_get_stats(res);
		MeshModel* dst = md.addNewMesh("", src->label() + " (vstree reconstruction)", true);
		fromVstree(vstree_reconstruct_result_get_mesh(res), dst->cm);
		logf("VS-Tree reconstruction: %llu points -> %llu vertices, %llu triangles; base mesh %llu "
			"triangles (genus %d%s), %u levels (stopped: %s%s), RMS error %.3g of the diagonal, %llu "
			"normals estimated, %.3f s",
			(unsigned long long)a.vertIndex.size(), (unsigned long long)s->output_vertices,
			(unsigned long long)s->output_triangles, (unsigned long long)s->base_triangles,
			s->base_genus, s->thickened ? ", thin parts thickened" : "", s->levels,
			vstree_refinement_stopped_str(s->stopped),
			s->stopped == VSTREE_REFINEMENT_STOPPED_TRIANGLE_BUDGET ? "; raise the error bound" : "",
			s->final_error, (unsigned long long)s->normals_estimated, s->seconds_total);
		if (s->input_points > s->samples)
			logf("%llu isolated points left out (far from the rest for their neighbours' spacing)",
				(unsigned long long)(s->input_points - s->samples));
		out["output_vertices"] = QVariant(int(s->output_vertices));
		out["output_triangles"] = QVariant(int(s->output_triangles));
		out["levels"] = QVariant(int(s->levels));
		out["base_genus"] = QVariant(int(s->base_genus));
		out["final_error"] = QVariant(s->final_error);
		out["stopped"] = QVariant(int(s->stopped));
		out["thickened"] = QVariant(int(s->thickened));
		out["normals_estimated"] = QVariant(int(s->normals_estimated));
		out["new_mesh_id"] = QVariant(dst->id());
		break;
	}
	case FP_COLOUR: {
		MeshHandle in;
		makeInput(a, passNormals, in);
		const vstree_simplify_params p = simplifyParams(par, double(src->cm.bbox.Diag()));
		vstree_tree* tree = nullptr;
		check(vstree_tree_build(in.p, &p, progressTrampoline, &prog, &tree), "tree_build");
		struct Free { vstree_tree* t; ~Free() { vstree_tree_free(t); } } guard{tree};
		const int32_t kind = par.getEnum("label") == 1 ? VSTREE_LABEL_KIND_T_NODE : VSTREE_LABEL_KIND_CLUSTER;
		std::vector<uint32_t> labels(vstree_tree_vertex_count(tree));
		check(vstree_tree_copy_vertex_labels(tree, kind, labels.data(), labels.size()), "copy_vertex_labels");
		if (labels.size() != a.vertIndex.size())
			throw MLException("vstree: label count does not match the vertex count");
		src->updateDataMask(MeshModel::MM_VERTCOLOR);
		size_t unlabelled = 0;
		uint32_t maxLabel = 0;
		for (size_t i = 0; i < labels.size(); ++i) {
			auto& v = src->cm.vert[a.vertIndex[i]];
			if (labels[i] == VSTREE_NO_INDEX) {
				v.C() = vcg::Color4b(128, 128, 128, 255);
				++unlabelled;
				continue;
			}
			maxLabel = std::max(maxLabel, labels[i]);
			const uint32_t h = hashColour(labels[i] + 1);
			v.C() = vcg::Color4b((h & 0xff) | 0x20, ((h >> 8) & 0xff) | 0x20, ((h >> 16) & 0xff) | 0x20, 255);
		}
		const vstree_tree_stats* s = vstree_tree_get_stats(tree);
		logf("VS-Tree colouring by %s: %llu clusters, %llu T-nodes, %llu unlabelled vertices, max "
			"cluster error %.3g",
			kind == VSTREE_LABEL_KIND_T_NODE ? "T-node" : "cluster", (unsigned long long)s->clusters,
			(unsigned long long)s->t_nodes, (unsigned long long)unlabelled, s->max_cluster_error);
		out["clusters"] = QVariant(int(s->clusters));
		out["t_nodes"] = QVariant(int(s->t_nodes));
		out["unlabelled"] = QVariant(int(unlabelled));
		break;
	}
	default: throw MLException(QString("vstree: unknown filter %1").arg(filter));
	}
	if (cb != nullptr)
		cb(100, "vstree: done");
	return out;
}

// The overrides of the interface the plugin is built for (meshlab_compat.h).
#if VSTREE_MESHLAB_2020
FilterPlugin::FilterClass FilterVstreePlugin::getClass(QAction* a) { return filterClass(ID(a)); }
FilterPlugin::FILTER_ARITY FilterVstreePlugin::filterArity(QAction*) const { return SINGLE_MESH; }
// Point clouds are valid input for all three; vstree itself reports what is missing.
int FilterVstreePlugin::getPreConditions(QAction*) const { return MeshModel::MM_NONE; }
int FilterVstreePlugin::postCondition(QAction* a) const { return postConditionOf(ID(a)); }

void FilterVstreePlugin::initParameterSet(QAction* a, MeshModel& m, RichParameterList& params)
{
	params = parameters(ID(a), m);
}

// 2020.09 has no error exceptions: the message goes to errorMessage (the GUI's error box) and
// to the log, since meshlabserver prints only "Problem with filter" and the log; the outputs
// go to the log too.
bool FilterVstreePlugin::applyFilter(QAction* action, MeshDocument& md, const RichParameterList& par, vcg::CallBackPos* cb)
{
	try {
		for (const auto& kv : apply(ID(action), par, md, cb))
			logf("%s = %s", kv.first.c_str(), qUtf8Printable(kv.second.toString()));
		return true;
	} catch (const MLException& e) {
		errorMessage = QString::fromLocal8Bit(e.what());
		logf("%s", e.what());
		return false;
	}
}
#else
QString FilterVstreePlugin::vendor() const { return "vstree"; }

QString FilterVstreePlugin::pythonFilterName(ActionIDType f) const
{
	switch (f) {
	case FP_SIMPLIFY: return "vstree_clustering_simplification";
	case FP_RECONSTRUCT: return "vstree_surface_reconstruction";
	case FP_COLOUR: return "vstree_cluster_colouring";
	default: return FilterPlugin::pythonFilterName(f);
	}
}

FilterPlugin::FilterClass FilterVstreePlugin::getClass(const QAction* a) const { return filterClass(ID(a)); }
FilterPlugin::FilterArity FilterVstreePlugin::filterArity(const QAction*) const { return SINGLE_MESH; }
// Point clouds are valid input for all three; vstree itself reports what is missing.
int FilterVstreePlugin::getPreConditions(const QAction*) const { return MeshModel::MM_NONE; }
int FilterVstreePlugin::postCondition(const QAction* a) const { return postConditionOf(ID(a)); }

RichParameterList FilterVstreePlugin::initParameterList(const QAction* a, const MeshModel& m)
{
	return parameters(ID(a), m);
}

std::map<std::string, QVariant> FilterVstreePlugin::applyFilter(
	const QAction*           action,
	const RichParameterList& par,
	MeshDocument&            md,
	unsigned int&            /*postConditionMask*/,
	vcg::CallBackPos*        cb)
{
	return apply(ID(action), par, md, cb);
}
#endif

MESHLAB_PLUGIN_NAME_EXPORTER(FilterVstreePlugin)
