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
	echo "== MeshLab plugin: pymeshlab $v: tests"
	VSTREE_MESHLAB_PLUGIN="target/meshlab/$v/pkg/libfilter_vstree.so" \
		"target/meshlab/$v/venv/bin/python" tests/meshlab/test_vstree_meshlab.py
done
