#!/usr/bin/env bash
# SPDX-License-Identifier: GPL-3.0-or-later
# Builds the vstree MeshLab plugin for both pinned pymeshlab hosts and runs the plugin tests
# in each host's venv. Everything is downloaded/built under target/meshlab/.
# env: MESHLAB_VERSIONS="2022.2.post4 2025.7.post1" (default both), plus build.sh's env.
set -euo pipefail
cd "$(dirname "$0")/../.."
versions="${MESHLAB_VERSIONS:-2022.2.post4 2025.7.post1}"
first=1
for v in $versions; do
	echo "== MeshLab plugin: pymeshlab $v: build"
	# libvstree is built once; the second host reuses target/release
	if [ $first = 1 ]; then
		bash plugins/meshlab/build.sh "$v"
	else
		VSTREE_NO_BUILD=1 bash plugins/meshlab/build.sh "$v"
	fi
	first=0
	echo "== MeshLab plugin: pymeshlab $v: tests (plugin from the unpacked package)"
	# the package must work on its own: plugin + libvstree.so.0 found through RUNPATH $ORIGIN
	unpacked="target/meshlab/$v/unpacked"
	rm -rf "$unpacked"
	mkdir -p "$unpacked"
	tar -xzf "target/meshlab/$v/vstree-meshlab-$v.tar.gz" -C "$unpacked"
	VSTREE_MESHLAB_PLUGIN="$unpacked/libfilter_vstree.so" \
		"target/meshlab/$v/venv/bin/python" tests/meshlab/test_vstree_meshlab.py
done
# Bad plugins: each host is given the other version's plugin, and its own without the library.
for v in $versions; do
	for other in $versions; do
		[ "$other" = "$v" ] && continue
		echo "== MeshLab plugin: pymeshlab $v: the $other plugin, and a plugin without libvstree"
		lone="target/meshlab/$v/lone"
		rm -rf "$lone"
		mkdir -p "$lone"
		cp "target/meshlab/$v/unpacked/libfilter_vstree.so" "$lone/"
		"target/meshlab/$v/venv/bin/python" tests/meshlab/test_load_failures.py \
			"target/meshlab/$other/unpacked/libfilter_vstree.so" "$lone/libfilter_vstree.so"
	done
done
