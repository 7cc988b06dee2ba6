"""The runtime's C ABI is declared once (reactor.kernels.abi): the ctypes classes, the IR types and
the C declarations derived from it agree on every field's offset and on each structure's size."""
import ctypes
import shutil
import subprocess

import llvmlite.binding as llvm
import pytest

from reactor.kernels import abi

STRUCTS = [abi.SETTINGS, abi.LOOP_CONFIG, abi.ERROR_LOOP, abi.TASK]


@pytest.mark.parametrize("struct", STRUCTS, ids=lambda s: s.name)
def test_ctypes_follow_the_declaration(struct):
    assert [f for f, _ in struct.ctype._fields_] == list(struct.names)
    offsets = [getattr(struct.ctype, f).offset for f in struct.names]
    assert offsets == sorted(offsets) and len(set(offsets)) == len(offsets)


@pytest.mark.parametrize("struct", STRUCTS, ids=lambda s: s.name)
def test_the_ir_type_has_the_ctypes_layout(struct):
    llvm.initialize_native_target()
    machine = llvm.Target.from_default_triple().create_target_machine()
    module = llvm.parse_assembly(f"@g = external global {struct.ir.ir}\n")
    ty = module.get_global_variable("g").global_value_type
    data = machine.target_data
    assert data.get_abi_size(ty) == ctypes.sizeof(struct.ctype)
    assert [data.get_element_offset(ty, k) for k in range(len(struct.names))] == \
        [getattr(struct.ctype, f).offset for f in struct.names]


@pytest.mark.skipif(shutil.which("cc") is None, reason="no C compiler")
def test_the_c_declarations_have_the_ctypes_layout(tmp_path):
    checks = "\n".join(f'    printf("%zu\\n", offsetof(struct {s.name}, {f}));' for s in STRUCTS for f in s.names)
    source = ("#include <stddef.h>\n#include <stdint.h>\n#include <stdio.h>\n"
              + "\n".join(s.c for s in STRUCTS) + f"\nint main(void) {{\n{checks}\n    return 0;\n}}\n")
    (tmp_path / "layout.c").write_text(source)
    subprocess.run(["cc", "-o", str(tmp_path / "layout"), str(tmp_path / "layout.c")], check=True)
    got = [int(v) for v in subprocess.run([str(tmp_path / "layout")], capture_output=True, text=True,
                                          check=True).stdout.split()]
    assert got == [getattr(s.ctype, f).offset for s in STRUCTS for f in s.names]


def test_code_reaches_fields_by_name():
    with pytest.raises(ValueError):
        abi.SETTINGS.index("no_such_field")
    assert abi.LOOP_CONFIG.index("code") == len(abi.LOOP_CONFIG.names) - 1
