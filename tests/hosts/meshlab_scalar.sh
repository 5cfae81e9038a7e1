# shellcheck shell=bash
# meshlab_scalar PLUGIN.so: prints "float" or "double", the scalar type (MESHLAB_SCALAR) the
# MeshLab that ships PLUGIN.so (one of its own plugins, libfilter_clean.so) was built with;
# returns 1 when it cannot tell. Sourced by tests/hosts/run.sh and tests/hosts/meshlab2020.sh.
# Debian's desktop packages are float, pymeshlab's wheels double; a plugin of the other type is
# refused at load time (2022.02 and later) or reads the meshes wrongly (2020.09, no check).
#   2022.02 and 2025.07: getMLVersion() returns (version, builtWithDoublePrecision()), the latter
#     comparing the string of MESHLAB_SCALAR with "double". 2022.02's compiler folds it to a
#     constant stored in the returned pair (offset 0x20); 2025.07's keeps the comparison, with
#     the literals "float" and "double" (one "double" only when MESHLAB_SCALAR is double).
#   2020.09 has no getMLVersion(): filter_clean's SnapVertexBorder instantiates
#     vcg::GridStaticPtr<CFaceO, CMeshO::ScalarType>, exported as GridStaticPtrI6CFaceOfE (float)
#     or ...dE (double).
meshlab_scalar() {
    local ref=$1 syms bit literals
    syms=$(nm -D --defined-only "$ref" 2>/dev/null) || return 1
    if grep -q getMLVersion <<<"$syms"; then
        # shellcheck disable=SC2016 # sed patterns meant literally
        bit=$(objdump -d --no-show-raw-insn "$ref" |
            sed -n '/getMLVersion.*>:$/,/ret/p' | sed -n 's/.*movb *\$0x\([01]\),0x20(%rdi).*/\1/p' | head -n 1)
        if [ -z "$bit" ]; then
            # (not `strings | grep -q`: grep's early exit can fail the pipe under pipefail)
            literals=$(strings -n 5 "$ref")
            if grep -qx float <<<"$literals"; then
                bit=0
            elif grep -qx double <<<"$literals"; then
                bit=1
            fi
        fi
    else
        case $(grep -o 'GridStaticPtrI6CFaceO[fd]E' <<<"$syms" | sort -u) in
            GridStaticPtrI6CFaceOfE) bit=0 ;;
            GridStaticPtrI6CFaceOdE) bit=1 ;;
        esac
    fi
    case ${bit:-} in
        0) echo float ;;
        1) echo double ;;
        *) return 1 ;;
    esac
}
