"""LLVM intrinsics for compiled (numba) kernels, shared by every paper that needs them.

:func:`fma` is the correctly rounded ``x * y + z`` (one rounding). Kernels that replay numpy's
BLAS rounding of small matrix products (which contracts to fused multiply-adds) call it, so
that their numbers equal numpy's bit for bit.
"""

from __future__ import annotations

from llvmlite import ir as llvm_ir
from numba import types
from numba.extending import intrinsic

__all__ = ["fma"]


@intrinsic
def fma(typingctx, x, y, z):
    """Correctly rounded ``x * y + z`` (``llvm.fma.f64``), callable from compiled code only.

    Parameters
    ----------
    typingctx : numba typing context
        Supplied by numba.
    x, y, z : float64
        The operands (inside a compiled function: ``fma(x, y, z)``).

    Returns
    -------
    tuple
        The signature and the code generator numba's ``@intrinsic`` expects.
    """
    sig = types.float64(types.float64, types.float64, types.float64)

    def codegen(context, builder, signature, args):
        dbl = llvm_ir.DoubleType()
        fn = builder.module.declare_intrinsic("llvm.fma", [dbl], llvm_ir.FunctionType(dbl, [dbl, dbl, dbl]))
        return builder.call(fn, args)

    return sig, codegen
