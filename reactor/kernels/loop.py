"""The inner loop of a kernel, emitted as LLVM IR.

``void <name>.loop(char **args, npy_intp *dims, npy_intp *steps, void *data)``
is NumPy's ufunc loop signature. For ``n = dims[0]`` elements it runs:

* a width-W vector loop when every output is contiguous and every input is
  contiguous or (for one input at a time) a broadcast scalar (stride 0), as in
  ``pow(x, 2.2)``; the last ``n % W`` elements go through the same body with
  masked loads and stores. Not when an output starts inside an input, ahead
  of it (``ufunc.accumulate`` passes ``out[i-1]`` as input ``i``);
* otherwise a scalar loop that follows arbitrary (negative, zero, unaligned
  multiple) strides.

Floating-point exception flags are saved on entry and restored on exit (x86
MXCSR): masked-off tail lanes and the routines' special-value paths compute on
values whose flags mean nothing, so kernels report no floating-point warnings
through NumPy's ``errstate``.

The user's body is traced once per path, at the path's width.
"""
from __future__ import annotations

from llvmlite import ir

from ..dsl.types import VType
from ..dsl.values import to_ir, value_class
from ..errors import DSLTypeError, at_return_of
from ..ir import emitter as _em
from ..ir import ops

I64 = ir.IntType(64)
I32 = ir.IntType(32)
I8P = ir.IntType(8).as_pointer()


def _c64(v):
    return ir.Constant(I64, v)


class LoopEmitter:
    """Emits the loop function for a kernel body in a module."""

    def __init__(self, module, name: str, body, in_kinds, out_kinds, width: int):
        self.body, self.ins, self.outs, self.width = body, in_kinds, out_kinds, width
        self.em = _em.FunctionEmitter(module, name, ir.VoidType(),
                                      [I8P.as_pointer(), I64.as_pointer(), I64.as_pointer(), I8P],
                                      ["args", "dims", "steps", "data"])
        self.em.dsl_function = _KernelBody(name.removesuffix(".loop"))

    def emit(self) -> ir.Function:
        from ..dsl.control import check_python_returns
        check_python_returns(self.body)
        em = self.em
        with em:
            args, dims, steps, _ = em.function.args
            nargs = len(self.ins) + len(self.outs)
            self.n = em.emit("load", dims, name="n")
            self.ptrs, self.steps = [], []
            for k in range(nargs):
                self.ptrs.append(em.emit("load", em.emit("gep", args, [_c64(k)], name=f"argp{k}"), name=f"arg{k}"))
                self.steps.append(em.emit("load", em.emit("gep", steps, [_c64(k)], name=f"stepp{k}"), name=f"step{k}"))
            flags = self._save_fp_flags()
            end = em.new_block("done")
            patterns = self._patterns() if self.width > 1 else ()
            strided = em.new_block("strided")
            if patterns:
                layouts = em.new_block("layouts")
                em.cbranch(self._operands_apart(), layouts, strided)
                em.goto(layouts)
            for pattern in patterns:
                cond = self._pattern_test(pattern)
                vec, nxt = em.new_block("vector"), em.new_block("next")
                em.cbranch(cond, vec, nxt)
                em.goto(vec)
                self._vector_loop(pattern)
                em.branch_to(end)
                em.goto(nxt)
            em.branch_to(strided)
            em.goto(strided)
            self._strided_loop()
            em.branch_to(end)
            em.goto(end)
            self._restore_fp_flags(flags)
            em.ret(None)
            em.finish()
        return em.function

    # -- floating-point status ---------------------------------------------------
    def _save_fp_flags(self):
        if not self.em.module.module.triple.startswith(("x86_64", "i686")):
            return None
        slot = self.em.alloca(ir.IntType(32), "mxcsr")
        fn = self.em.intrinsic("llvm.x86.sse.stmxcsr", ir.VoidType(), [I8P])
        self.em.call(fn, [self.em.emit("bitcast", slot, I8P, name="mxcsr.p")])
        return slot

    def _restore_fp_flags(self, slot):
        if slot is not None:
            fn = self.em.intrinsic("llvm.x86.sse.ldmxcsr", ir.VoidType(), [I8P])
            self.em.call(fn, [self.em.emit("bitcast", slot, I8P, name="mxcsr.p")])

    # -- layout patterns -----------------------------------------------------
    def _patterns(self):
        """Input layouts with a vector path: all contiguous, or one input broadcast."""
        nin = len(self.ins)
        pats = [("contig",) * nin]
        if nin >= 2:
            for k in range(nin):
                pats.append(tuple("bcast" if j == k else "contig" for j in range(nin)))
        return pats

    def _pattern_test(self, pattern):
        em = self.em
        cond = ir.Constant(ir.IntType(1), 1)
        layouts = list(pattern) + ["contig"] * len(self.outs)
        for k, (layout, kind) in enumerate(zip(layouts, self.ins + self.outs)):
            want = 0 if layout == "bcast" else kind.mem_bytes
            ok = em.emit("icmp_signed", "==", self.steps[k], _c64(want), name=f"{layout}{k}")
            cond = em.emit("and_", cond, ok, name="layout_ok")
        return cond

    def _operands_apart(self):
        """No output starts inside the n elements of an input, ahead of the input's
        start, where the vector loop would read inputs before the strided loop's
        element-by-element order has written them: ufunc.accumulate passes out[i-1]
        as input i. (For ordinary calls NumPy copies overlapping operands.)"""
        em = self.em
        addr = [em.emit("ptrtoint", p, I64, name=f"addr{k}") for k, p in enumerate(self.ptrs)]
        ok = ir.Constant(ir.IntType(1), 1)
        for a, kind in enumerate(self.ins):
            last = em.emit("sub", em.emit("mul", self.n, _c64(kind.mem_bytes), name="bytes"), _c64(1), name="last")
            for b in range(len(self.ins), len(self.ptrs)):
                ahead = em.emit("sub", em.emit("sub", addr[b], addr[a], name="gap"), _c64(1), name="ahead")
                ok = em.emit("and_", ok, em.emit("icmp_unsigned", ">=", ahead, last, name="apart"), name="apart_ok")
        return ok

    # -- vector path --------------------------------------------------------------
    def _vector_loop(self, pattern):
        em, W = self.em, self.width
        i = em.alloca(I64, "i")
        em.emit("store", _c64(0), i)
        head, body, tail_test = em.new_block("vec.cond"), em.new_block("vec.body"), em.new_block("vec.tail.test")
        em.branch_to(head)
        em.goto(head)
        iv = em.emit("load", i, name="i")
        room = em.emit("icmp_signed", "<=", em.emit("add", iv, _c64(W), name="i_end"), self.n, name="full")
        em.cbranch(room, body, tail_test)
        em.goto(body)
        iv = em.emit("load", i, name="i")
        self._vector_step(pattern, iv, mask=None)
        em.emit("store", em.emit("add", iv, _c64(W), name="i_next"), i)
        em.branch_to(head)
        # masked tail
        em.goto(tail_test)
        iv = em.emit("load", i, name="i")
        tail, done = em.new_block("vec.tail"), em.new_block("vec.done")
        em.cbranch(em.emit("icmp_signed", "<", iv, self.n, name="has_tail"), tail, done)
        em.goto(tail)
        lanes = ir.Constant(ir.VectorType(I64, W), [_c64(j) for j in range(W)])
        idx = em.emit("add", ops.splat(em, W, iv), lanes, name="lane_i")
        mask = em.emit("icmp_signed", "<", idx, ops.splat(em, W, self.n), name="tail_mask")
        self._vector_step(pattern, iv, mask=mask)
        em.branch_to(done)
        em.goto(done)

    def _vector_step(self, pattern, iv, mask):
        em, W = self.em, self.width
        inputs = []
        for k, (layout, kind) in enumerate(zip(pattern, self.ins)):
            vt = VType(kind, W)
            if layout == "bcast":
                raw = em.emit("load", em.emit("bitcast", self.ptrs[k], kind.mem_type.as_pointer(), name=f"s{k}"),
                              name=f"in{k}", align=kind.mem_bytes)
                raw = ops.splat(em, W, raw)
            else:
                raw = self._vector_memop(k, kind, iv, mask, None)
            inputs.append(_from_memory(em, kind, vt, raw, f"x{k}"))
        results = self._trace(inputs, W)
        for j, (kind, value) in enumerate(zip(self.outs, results)):
            k = len(self.ins) + j
            self._vector_memop(k, kind, iv, mask, _to_memory(em, kind, value))

    def _vector_memop(self, k, kind, iv, mask, store_value):
        """Load (store_value None) or store W elements of argument k at element iv."""
        em, W = self.em, self.width
        mem_vt = ir.VectorType(kind.mem_type, W)
        off = em.emit("mul", iv, _c64(kind.mem_bytes), name="off")
        addr = em.emit("gep", self.ptrs[k], [off], name=f"p{k}")
        vptr = em.emit("bitcast", addr, mem_vt.as_pointer(), name=f"v{k}")
        align = ir.Constant(I32, kind.mem_bytes)
        if mask is None:
            if store_value is None:
                return em.emit("load", vptr, name=f"in{k}", align=kind.mem_bytes)
            return em.emit("store", store_value, vptr, align=kind.mem_bytes)
        vt_name = ops.mangle(mem_vt)
        if store_value is None:
            passthru = ir.Constant(mem_vt, None)
            fn = em.intrinsic(f"llvm.masked.load.{vt_name}.p0", mem_vt,
                              [mem_vt.as_pointer(), I32, mask.type, mem_vt])
            return em.call(fn, [vptr, align, mask, passthru], name=f"in{k}")
        fn = em.intrinsic(f"llvm.masked.store.{vt_name}.p0", ir.VoidType(),
                          [mem_vt, mem_vt.as_pointer(), I32, mask.type])
        return em.call(fn, [store_value, vptr, align, mask])

    # -- strided path -------------------------------------------------------
    def _strided_loop(self):
        em = self.em
        i = em.alloca(I64, "j")
        em.emit("store", _c64(0), i)
        head, body, done = em.new_block("strided.cond"), em.new_block("strided.body"), em.new_block("strided.done")
        em.branch_to(head)
        em.goto(head)
        iv = em.emit("load", i, name="j")
        em.cbranch(em.emit("icmp_signed", "<", iv, self.n, name="more"), body, done)
        em.goto(body)
        iv = em.emit("load", i, name="j")
        addrs = []
        for k, kind in enumerate(self.ins + self.outs):
            off = em.emit("mul", iv, self.steps[k], name="off")
            addrs.append(em.emit("bitcast", em.emit("gep", self.ptrs[k], [off], name=f"q{k}"),
                                 kind.mem_type.as_pointer(), name=f"e{k}"))
        inputs = []
        for k, kind in enumerate(self.ins):
            raw = em.emit("load", addrs[k], name=f"in{k}", align=1)
            inputs.append(_from_memory(em, kind, VType(kind, 1), raw, f"x{k}"))
        results = self._trace(inputs, 1)
        for j, (kind, value) in enumerate(zip(self.outs, results)):
            em.emit("store", _to_memory(em, kind, value), addrs[len(self.ins) + j], align=1)
        em.emit("store", em.emit("add", iv, _c64(1), name="j_next"), i)
        em.branch_to(head)
        em.goto(done)

    # -- the user's body --------------------------------------------------------
    def _trace(self, inputs, width):
        em = self.em
        em.width = width
        scope = em.push_scope("kernel body")
        try:
            result = self.body(*inputs)
        finally:
            em.width = self.width
        if not isinstance(result, tuple):
            result = (result,)
        with at_return_of(self.body):
            if len(result) != len(self.outs):
                raise DSLTypeError(f"kernel body returned {len(result)} value(s); its signature declares "
                                   f"{len(self.outs)} output(s)")
            irs = [to_ir(r, VType(kind, width)) for r, kind in zip(result, self.outs)]
        em.pop_scope(scope)
        return irs


class _KernelBody:
    """Stands in for the function being built: kernel bodies return with Python ``return``."""

    returns = None
    is_kernel = True  # Return() is an error in kernel bodies

    def __init__(self, name):
        self.name = name


def _from_memory(em, kind, vt, raw, name):
    if kind.category == "bool":
        zero = ir.Constant(raw.type, 0 if vt.width == 1 else [ir.Constant(ir.IntType(8), 0)] * vt.width)
        raw = em.emit("icmp_unsigned", "!=", raw, zero, name=name)
    return value_class(vt)._wrap(raw, em).named(name)


def _to_memory(em, kind, value_ir):
    if kind.category == "bool":
        return em.emit("zext", value_ir, ir.VectorType(ir.IntType(8), value_ir.type.count)
                       if isinstance(value_ir.type, ir.VectorType) else ir.IntType(8), name="byte")
    return value_ir


def emit_dispatcher(module, name: str, serial: ir.Function) -> ir.Function:
    """``<name>.ufunc``: the loop NumPy calls. ``data`` points to a
    ``parallel.LoopConfig``; calls of at least ``*threshold`` elements go to its
    hook (which splits them across threads), all others straight to ``serial``."""
    em = _em.FunctionEmitter(module, name, ir.VoidType(),
                             [I8P.as_pointer(), I64.as_pointer(), I64.as_pointer(), I8P],
                             ["args", "dims", "steps", "data"])
    serial.attributes.add("noinline")  # else LLVM copies the whole loop here: twice the machine code
    loop_ty = serial.function_type
    cfg_ty = ir.LiteralStructType([I8P, loop_ty.as_pointer(), I64.as_pointer(), I64])
    with em:
        args, dims, steps, data = em.function.args
        cfg = em.emit("bitcast", data, cfg_ty.as_pointer(), name="config")
        field = lambda i, what: em.emit("load", em.emit("gep", cfg, [ir.Constant(I32, 0), ir.Constant(I32, i)],
                                                        name=f"{what}.p"), name=what)
        hook = field(1, "hook")
        threshold = em.emit("load", field(2, "threshold.addr"), name="threshold")
        n = em.emit("load", dims, name="n")
        big = em.emit("icmp_signed", ">=", n, threshold, name="big")
        parallel, serial_block = em.new_block("parallel"), em.new_block("serial")
        em.cbranch(big, parallel, serial_block)
        em.goto(parallel)
        em.call(hook, [args, dims, steps, data])
        em.ret(None)
        em.goto(serial_block)
        em.call(serial, [args, dims, steps, data])
        em.ret(None)
        em.finish()
    return em.function
