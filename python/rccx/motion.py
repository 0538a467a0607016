"""Position equations written as RCCL writes them, over rccx's C++ transforms.

    T6 = rccx.t6()
    TOOL = rccx.const("TOOL", tool)
    P = rccx.position("P", T6 * TOOL == BASE.inv() * CONV * PART)
    # the same as RCCL's  BASE T6 TOOL = CONV PART  (tool TOOL)

A product of transforms (`A * B`, `X.inv()`) compared with `==` gives an Equation; position()
makes the C++ rccl::Position of it. C++ equations have no inverses: an inverse standing at either
end of a side moves to the other side (RCCL's own way of writing them), one inside a side raises
rccx.EquationError. The tool is the left side's last transform after T6 as written (T6 itself
when none), unless tool= names it.
"""

from . import _rccx

Transform = _rccx.Transform

# The bound classes and factories, here as well as in rccx, so that this module has what its
# stub (motion.pyi) declares.
from ._rccx import (Arm, Cell, CellFileError, EquationError, Event, Gate, LogError,  # noqa: E402
                    Motion, MotionError, Position, Robot, SessionError, Stream, Together, When,
                    const, external_wrench, hold, joints, stream, t6, wrench_at_tool)

__all__ = ["Arm", "Cell", "CellFileError", "Equation", "EquationError", "Event", "Factor", "Gate",
           "LogError", "Motion", "MotionError", "Position", "Product", "Robot", "SessionError",
           "Stream", "Together", "Transform", "When", "const", "hold", "joints", "position",
           "stream", "t6", "external_wrench", "wrench_at_tool"]


class Factor:
    """One transform of a product, possibly inverted."""

    __slots__ = ("transform", "inverted")

    def __init__(self, transform, inverted=False):
        self.transform = transform
        self.inverted = inverted

    def flipped(self):
        return Factor(self.transform, not self.inverted)

    def __repr__(self):
        return self.transform.name + ("^-1" if self.inverted else "")


def _factors(x):
    if isinstance(x, Transform):
        return (Factor(x),)
    if isinstance(x, Product):
        return x.factors
    raise TypeError(f"an equation multiplies rccx transforms (rccx.const, hold, stream, t6, "
                    f"a cell's tool_frame), not {type(x).__name__}")


class Product:
    """Transforms multiplied left to right; `==` with another product gives an Equation."""

    __slots__ = ("factors",)
    __hash__ = None

    def __init__(self, factors):
        self.factors = tuple(factors)

    def __mul__(self, other):
        return Product(self.factors + _factors(other))

    def __rmul__(self, other):
        return Product(_factors(other) + self.factors)

    def inv(self):
        return Product(f.flipped() for f in reversed(self.factors))

    def __eq__(self, other):
        return Equation(self, Product(_factors(other)))

    def __repr__(self):
        return " ".join(map(repr, self.factors))


class Equation:
    """lhs == rhs, both products of transforms; rccx.position(name, eq) makes the Position."""

    __slots__ = ("lhs", "rhs")

    def __init__(self, lhs, rhs):
        self.lhs = Product(_factors(lhs))
        self.rhs = Product(_factors(rhs))

    def __bool__(self):
        # `a == b` on two transforms gives an Equation; as a truth value (in `x in list`) it
        # is identity, as Python's default ==.
        lf, rf = self.lhs.factors, self.rhs.factors
        return (len(lf) == 1 and len(rf) == 1 and lf[0].transform is rf[0].transform
                and lf[0].inverted == rf[0].inverted)

    def __repr__(self):
        return f"Equation({self.lhs!r} = {self.rhs!r})"


def _transform_mul(self, other):
    return Product((Factor(self),) + _factors(other))


def _transform_rmul(self, other):
    return Product(_factors(other) + (Factor(self),))


def _transform_eq(self, other):
    if not isinstance(other, (Transform, Product)):
        return NotImplemented
    return Equation(Product((Factor(self),)), Product(_factors(other)))


def _transform_inv(self):
    return Product((Factor(self, True),))


Transform.__mul__ = _transform_mul
Transform.__rmul__ = _transform_rmul
Transform.__eq__ = _transform_eq
Transform.__ne__ = lambda self, other: not bool(_transform_eq(self, other))
Transform.__hash__ = lambda self: id(self)
Transform.inv = _transform_inv


def _is_t6(f):
    return f.transform.kind == "T6"


def _normalise(lhs, rhs):
    """The equation with T6 on the left and no inverse: (lhs, rhs, default tool)."""
    lhs, rhs = list(lhs), list(rhs)
    if not any(_is_t6(f) for f in lhs) and any(_is_t6(f) for f in rhs):
        lhs, rhs = rhs, lhs
    t6 = [i for i, f in enumerate(lhs) if _is_t6(f)]
    if len(t6) == 1 and lhs[t6[0]].inverted:
        raise _rccx.EquationError("T6 stands inverted: write the equation with T6 itself")
    # The tool as written: the last transform after T6 on the left, T6 when none.
    tool = None
    if len(t6) == 1:
        after = lhs[t6[0] + 1:]
        tool = after[-1].transform if after and not after[-1].inverted else lhs[t6[0]].transform
    for _ in range(8):
        t = next((i for i, f in enumerate(lhs) if _is_t6(f)), None)
        if t is None:
            break
        pre, post = lhs[:t], lhs[t + 1:]
        inv_pre = [i for i, f in enumerate(pre) if f.inverted]
        inv_post = [i for i, f in enumerate(post) if f.inverted]
        if inv_pre:  # A^-1 T6 = R  ->  T6 = A R
            k = inv_pre[-1] + 1
            rhs = [f.flipped() for f in reversed(pre[:k])] + rhs
            lhs = lhs[k:]
            continue
        if inv_post:  # T6 B^-1 = R  ->  T6 = R B
            k = t + 1 + inv_post[0]
            rhs = rhs + [f.flipped() for f in reversed(lhs[k:])]
            lhs = lhs[:k]
            continue
        if rhs and rhs[0].inverted:  # T6 = C^-1 R  ->  C T6 = R
            k = next((i for i, f in enumerate(rhs) if not f.inverted), len(rhs))
            lhs = [f.flipped() for f in reversed(rhs[:k])] + lhs
            rhs = rhs[k:]
            continue
        if rhs and rhs[-1].inverted:  # T6 = R C^-1  ->  T6 C = R
            k = max(i for i, f in enumerate(rhs) if not f.inverted) + 1 \
                if any(not f.inverted for f in rhs) else 0
            lhs = lhs + [f.flipped() for f in reversed(rhs[k:])]
            rhs = rhs[:k]
            continue
        break
    for side, name in ((lhs, "left"), (rhs, "right")):
        for f in side:
            if f.inverted:
                raise _rccx.EquationError(
                    f"{f.transform.name}.inv() stands inside the {name} side; RCCL's equations "
                    f"have no inverses: move {f.transform.name} to the other side's end")
    return lhs, rhs, tool


def position(name, equation=None, *, lhs=None, rhs=None, tool=None):
    """The position `name` of an equation (RCCL's makeposition).

    equation: `T6 * TOOL == A * B` (rccx.Equation); or lhs= and rhs= lists of transforms
    (lhs holding T6). tool: the transform of the left side, at or after T6, whose frame moves
    on straight lines in Cartesian mode (default: the left side's last, T6 when none).
    Raises rccx.EquationError (a ValueError) with rccx's message for a malformed equation.
    """
    if equation is not None:
        if lhs is not None or rhs is not None:
            raise TypeError("position: give an equation or lhs= and rhs=, not both")
        if not isinstance(equation, Equation):
            raise TypeError("position: the equation is written `T6 * TOOL == A * B` "
                            f"(got {type(equation).__name__})")
        left, right = equation.lhs.factors, equation.rhs.factors
    else:
        if lhs is None or rhs is None:
            raise TypeError("position: give an equation, or lhs= and rhs= (lists of transforms)")
        left = tuple(f for x in lhs for f in _factors(x))
        right = tuple(f for x in rhs for f in _factors(x))
    left, right, written_tool = _normalise(left, right)
    return _rccx._make_position(name, [f.transform for f in left], [f.transform for f in right],
                                tool if tool is not None else written_tool)
