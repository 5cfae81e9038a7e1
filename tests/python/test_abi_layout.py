"""The ctypes structs of the binding against the C header: a small C program, compiled against
include/vstree.h, prints every struct's size and every field's offset, and the binding's
Structure classes must agree field by field. A field added in Rust (and so in the generated
header) but not in Python, or in another place, fails here instead of silently misaligning."""

import ctypes
import os
import re
import shutil
import subprocess

import pytest

from vstree import _ffi
from conftest import ROOT

# C struct name -> the binding's class.
STRUCTS = {
    "vstree_simplify_params": _ffi.SimplifyParams,
    "vstree_simplify_stats": _ffi.SimplifyStats,
    "vstree_tree_stats": _ffi.TreeStats,
    "vstree_node": _ffi.Node,
    "vstree_t_node": _ffi.TNode,
    "vstree_tree_level": _ffi.TreeLevel,
    "vstree_normal_params": _ffi.NormalParams,
    "vstree_normals_report": _ffi.NormalsReport,
    "vstree_reconstruct_params": _ffi.ReconstructParams,
    "vstree_reconstruct_stats": _ffi.ReconstructStats,
    "vstree_param_info": _ffi.ParamInfo,
    "vstree_param_choice": _ffi.ParamChoice,
}


def header_fields():
    """{struct: [field, ...]} in declaration order, read from the header."""
    header = open(os.path.join(ROOT, "include", "vstree.h")).read()
    header = re.sub(r"/\*.*?\*/", "", header, flags=re.S)
    found = {}
    for name, body in re.findall(r"typedef struct (\w+) \{(.*?)\} \1;", header, flags=re.S):
        found[name] = [m.group(1) for m in re.finditer(r"(\w+)(?:\[\d+\])?;", body)]
    return found


@pytest.fixture(scope="module")
def c_layout(tmp_path_factory):
    """{struct: (size, {field: offset})} as the C compiler lays them out."""
    compiler = shutil.which("cc")
    if compiler is None:
        pytest.fail("no C compiler (cc) to check the binding's structs against the header")
    fields = header_fields()
    lines = ["#include <stddef.h>", "#include <stdio.h>", "#include <vstree.h>", "int main(void) {"]
    for struct, names in fields.items():
        lines.append('  printf("%s size %%zu\\n", sizeof(%s));' % (struct, struct))
        for field in names:
            lines.append('  printf("%s %s %%zu\\n", offsetof(%s, %s));' % (struct, field, struct, field))
    lines += ["  return 0;", "}"]
    folder = tmp_path_factory.mktemp("layout")
    source, program = folder / "layout.c", folder / "layout"
    source.write_text("\n".join(lines) + "\n")
    subprocess.run(
        [compiler, "-std=c99", "-I", os.path.join(ROOT, "include"), str(source), "-o", str(program)], check=True
    )
    layout = {}
    for line in subprocess.run([str(program)], check=True, capture_output=True, text=True).stdout.splitlines():
        struct, field, value = line.split()
        offsets = layout.setdefault(struct, [None, {}])[1]
        if field == "size":
            layout[struct][0] = int(value)
        else:
            offsets[field] = int(value)
    return layout


def test_every_struct_of_the_header_has_a_binding_class():
    assert set(header_fields()) == set(STRUCTS)


@pytest.mark.parametrize("struct", sorted(STRUCTS))
def test_binding_structs_match_the_header(struct, c_layout):
    cls = STRUCTS[struct]
    size, offsets = c_layout[struct]
    names = [f[0] for f in cls._fields_]
    assert names == list(offsets), "%s: fields differ from the header's" % struct
    for name in names:
        assert getattr(cls, name).offset == offsets[name], "%s.%s" % (struct, name)
    assert ctypes.sizeof(cls) == size, struct
