"""Straight-line numeric code compiled without numba's typing of every statement.

A generated model's functions and the written-out linear algebra (:mod:`.linalg`,
:mod:`.rhs`) are thousands of statements such as ``e12 = e3 * psi_dot`` or
``s = fma(a, b, s)`` on array entries indexed by constants.  numba compiles such a
function statement by statement: it types every operator and call by trying its overloads
in turn, then looks them up again to lower them, which made most of a coupled
mechanism's first ensemble.  The types in such code follow
from the arguments' alone, so :func:`emitted` types it in one pass of its own, asking
numba's typing only once for each distinct operation and argument types (``float64 *
float64``), and lowers it with numba's own implementations of those operations, called as
numba's lowering calls them (the operands cast to the signature's types): the same
instructions for LLVM, so the same numbers bit for bit.

The accepted language is what the generators write:

* statements: ``name = expr``, ``a, b = x, y``, ``array[i, j] = expr`` with constant
  indices, ``array[:] = x`` and ``array[:, :] = x`` (every entry), ``name op= expr``, and a
  ``return`` at the end;
* expressions: names (arguments, earlier assignments, numbers and modules of the
  function's globals), number constants, ``array[i, j]`` with constant non-negative
  indices, ``+ - * / **``, unary ``-`` and ``+``, ``not``, ``&``, one comparison, and
  calls of ``abs``, ``max``, ``min``, functions of :mod:`math` and compiled (``@njit``)
  functions with fixed arguments.

Anything else is refused (``NotImplementedError``) when the function is emitted, never
guessed at; the caller then compiles the function with numba as it is.
"""

from __future__ import annotations

import ast
import builtins
import inspect
import math
import operator
import textwrap
import types as pytypes
from functools import cache

from numba import types
from numba.core import cgutils
from numba.core.dispatcher import Dispatcher
from numba.extending import intrinsic

from .fma import HOST_FMA

__all__ = ["emitted", "emitted_source"]


class _Refused(NotImplementedError):
    pass


_BINARY = {ast.Add: operator.add, ast.Sub: operator.sub, ast.Mult: operator.mul,
           ast.Div: operator.truediv, ast.Pow: operator.pow, ast.BitAnd: operator.and_}
_INPLACE = {ast.Add: operator.iadd, ast.Sub: operator.isub, ast.Mult: operator.imul,
            ast.Div: operator.itruediv}
_UNARY = {ast.USub: operator.neg, ast.UAdd: operator.pos, ast.Not: operator.not_}
_COMPARE = {ast.Gt: operator.gt, ast.Lt: operator.lt, ast.GtE: operator.ge,
            ast.LtE: operator.le, ast.Eq: operator.eq, ast.NotEq: operator.ne}  # fmt: skip
_SYNTAX = (ast.FunctionDef, ast.arguments, ast.arg, ast.Assign, ast.AugAssign, ast.Expr,
           ast.Return, ast.Pass, ast.Name, ast.Load, ast.Store, ast.Constant, ast.Call,
           ast.BinOp, ast.UnaryOp, ast.Compare, ast.Subscript, ast.Tuple, ast.Slice,
           ast.Attribute, *_BINARY, *_UNARY, *_COMPARE)  # fmt: skip
#: the written-out linear algebra's own functions (:mod:`.linalg`), by name
_SPECIAL = {"fma": 3, "fnma": 3, "_at1": 2, "_at2": 3, "_set1": 3, "_set2": 4}

#: numba's signature for each operation and argument types met so far
_SIGNATURES: dict = {}


def _signature(typingctx, fn, argtypes):
    key = (fn, argtypes)
    sig = _SIGNATURES.get(key)
    if sig is None:
        fnty = typingctx.resolve_value_type(fn)
        sig = typingctx.resolve_function_type(fnty, argtypes, {})
        if sig is None:
            raise _Refused(f"numba has no {getattr(fn, '__name__', fn)}{argtypes}")
        _SIGNATURES[key] = sig
    return sig


#: numba's implementation for each target context, operation and signature met so far
#: (numba looks one up at every call, a tenth of a millisecond: most of the lowering of
#: a generated model's thousands of operations)
_IMPLEMENTATIONS: dict = {}


def _implementation(context, fn, sig):
    key = (context, fn, sig)
    impl = _IMPLEMENTATIONS.get(key)
    if impl is None:
        fnty = context.typing_context.resolve_value_type(fn)
        impl = _IMPLEMENTATIONS[key] = context.get_function(fnty, sig)
    return impl


def _operation(node):
    """``(numba's function, operand nodes)`` of an operator's node, else None."""
    if isinstance(node, ast.BinOp):
        return _BINARY[type(node.op)], (node.left, node.right)
    if isinstance(node, ast.UnaryOp):
        return _UNARY[type(node.op)], (node.operand,)
    if isinstance(node, ast.Compare):
        return _COMPARE[type(node.ops[0])], (node.left, node.comparators[0])
    return None


def _operands(node) -> list:
    """The operand nodes of an operator's or a call's node, left to right."""
    operation = _operation(node)
    return list(operation[1]) if operation is not None else list(node.args)


#: what :meth:`_Walk.leaf` returns for a node whose value needs its operands'
_NOT_LEAF = object()


def _text(node, limit: int = 200) -> str:
    """``node`` as source for a message, cut to ``limit`` characters (a generated
    expression thousands deep is more than a message, and than ``ast.unparse``'s
    recursion, can hold)."""
    try:
        text = ast.unparse(node)
    except RecursionError:
        return f"a {type(node).__name__} nested too deep to print"
    return text if len(text) <= limit else text[:limit] + " …"


def _index(node) -> list:
    """A subscript's indices."""
    return node.elts if isinstance(node, ast.Tuple) else [node]


def _constant_type(typingctx, value):
    """A constant's type as numba's type inference gives it: Literal[int](2), float64."""
    return types.maybe_literal(value) or typingctx.resolve_value_type(value)


def _postorder(root):
    """Every node under ``root`` (itself last), children before their parent, left to
    right: the order a recursive walk would visit them, with a stack of its own (a
    generated expression may nest thousands deep, past Python's recursion limit)."""
    out, stack = [], [(root, False)]
    while stack:
        node, expanded = stack.pop()
        if expanded:
            out.append(node)
            continue
        stack.append((node, True))
        stack.extend((child, False) for child in reversed(list(ast.iter_child_nodes(node))))
    return out


def _folded(node):
    """``node`` itself, or the constant it folds to (its operands already folded)."""
    if isinstance(node, ast.UnaryOp):
        if (isinstance(node.op, (ast.USub, ast.UAdd)) and isinstance(node.operand, ast.Constant)
                and type(node.operand.value) in (int, float)):  # fmt: skip
            value = node.operand.value
            return ast.copy_location(ast.Constant(-value if isinstance(node.op, ast.USub)
                                                  else +value), node)  # fmt: skip
        return node
    if not isinstance(node, ast.BinOp):
        return node
    a, b = node.left, node.right
    if not (type(node.op) in _BINARY and isinstance(a, ast.Constant)
            and isinstance(b, ast.Constant) and type(a.value) in (int, float)
            and type(b.value) in (int, float)):  # fmt: skip
        return node
    try:
        value = _BINARY[type(node.op)](a.value, b.value)
    except (ArithmeticError, TypeError, ValueError):
        return node  # (CPython leaves it to run time too)
    if type(value) not in (int, float) or (type(value) is int and abs(value) >= 2**63):
        return node
    return ast.copy_location(ast.Constant(value), node)


def _fold(node):
    """Number constants folded as CPython folds them before numba sees the bytecode
    (``-2.0``, ``2 * 3``): the same constants, typed as numba types them.  Bottom-up over
    :func:`_postorder`, each node's fields pointed at its folded children."""
    replaced: dict = {}
    for each in _postorder(node):
        for field, value in ast.iter_fields(each):
            if isinstance(value, ast.AST) and id(value) in replaced:
                setattr(each, field, replaced[id(value)])
            elif isinstance(value, list):
                value[:] = [replaced.get(id(v), v) if isinstance(v, ast.AST) else v
                            for v in value]  # fmt: skip
        new = _folded(each)
        if new is not each:
            replaced[id(each)] = new
    return replaced.get(id(node), node)  # (never compiled by Python: no locations needed)


class _Function:
    """A straight-line function checked against the language, with what its names mean."""

    def __init__(self, fn_def: ast.FunctionDef, namespace: dict, fused: bool):
        self.fn_def, self.namespace, self.fused = _fold(fn_def), namespace, fused
        self.params = [a.arg for a in fn_def.args.args]
        a = fn_def.args
        if a.vararg or a.kwarg or a.kwonlyargs or a.defaults or a.posonlyargs:
            raise _Refused(f"{fn_def.name}'s arguments")
        body = list(self.fn_def.body)
        while body and isinstance(body[0], ast.Expr) and isinstance(body[0].value, ast.Constant):
            body = body[1:]  # a docstring
        self.ret = body.pop() if body and isinstance(body[-1], ast.Return) else None
        self.body = body
        self.assigned = set()
        for node in ast.walk(self.fn_def):
            nested = node is not self.fn_def and isinstance(node, ast.FunctionDef)
            if nested or not isinstance(node, _SYNTAX):
                raise _Refused(f"{type(node).__name__} in {fn_def.name}")
            if isinstance(node, ast.Name) and isinstance(node.ctx, ast.Store):
                self.assigned.add(node.id)
        defined = set(self.params)
        for stmt in body:
            self._check_statement(stmt, defined)
        if self.ret is not None and self.ret.value is not None:
            self._check_expr(self.ret.value, defined)

    def refuse(self, node):
        raise _Refused(f"{_text(node)} in {self.fn_def.name}")

    def global_(self, name):
        if name in self.namespace:
            return self.namespace[name]
        if hasattr(builtins, name):
            return getattr(builtins, name)
        raise _Refused(f"the name {name} in {self.fn_def.name}")

    def resolve(self, node):
        """The object a global name or a module's attribute stands for."""
        if isinstance(node, ast.Name):
            return self.global_(node.id)
        if isinstance(node, ast.Attribute) and isinstance(node.value, ast.Name):
            module = self.global_(node.value.id)
            if isinstance(module, pytypes.ModuleType) and hasattr(module, node.attr):
                return getattr(module, node.attr)
        self.refuse(node)

    def callee(self, call):
        if isinstance(call.func, ast.Name) and call.func.id in _SPECIAL and (
                call.func.id not in self.namespace):  # fmt: skip
            return call.func.id
        fn = self.resolve(call.func)
        of_math = isinstance(fn, pytypes.BuiltinFunctionType) and (
            fn is getattr(math, fn.__name__, None))  # fmt: skip
        if fn in (abs, max, min) or isinstance(fn, Dispatcher) or of_math:
            return fn
        self.refuse(call)

    def constant(self, node):
        """The number a name or attribute of the globals stands for, else None."""
        if isinstance(node, ast.Constant) and type(node.value) in (int, float, bool):
            return node.value
        if isinstance(node, (ast.Name, ast.Attribute)):
            try:
                value = self.resolve(node)
            except _Refused:
                return None
            if type(value) in (int, float, bool):
                return value
        return None

    def _check_expr(self, root, defined):
        """Refuse an expression outside the language (its nodes in a walk of its own: no
        recursion on its depth)."""
        todo = [root]
        while todo:
            node = todo.pop()
            todo.extend(reversed(self._checked_operands(node, defined)))

    def _checked_operands(self, node, defined) -> list:
        """Check ``node`` itself; the operands still to check."""
        if isinstance(node, ast.Name) and node.id in defined:
            return []
        if isinstance(node, ast.Name) and node.id in self.assigned:
            self.refuse(node)  # read before it is assigned
        if self.constant(node) is not None:
            return []
        if isinstance(node, ast.Subscript):
            self._entry(node, defined, store=False)
            return []
        if isinstance(node, ast.BinOp):
            if isinstance(node.op, ast.Pow) and not (isinstance(node.right, ast.Constant)
                                                     and type(node.right.value) in (int, float)):
                self.refuse(node)  # (numba may lower ``x ** c`` by c's value one day)
            return [node.left, node.right]
        if isinstance(node, ast.UnaryOp):
            return [node.operand]
        if isinstance(node, ast.Compare) and len(node.ops) == 1:
            return [node.left, node.comparators[0]]
        if isinstance(node, ast.Call) and not node.keywords:
            fn = self.callee(node)
            if (_SPECIAL.get(fn, len(node.args)) != len(node.args)
                    or (fn in (max, min) and len(node.args) != 2)):  # fmt: skip
                self.refuse(node)
            if fn in ("_set1", "_set2"):
                self.refuse(node)  # a statement, not a value
            if fn in ("_at1", "_at2"):
                self._array(node.args[0], defined)
                self._indices(node, node.args[1:], int(fn[-1]))
                return []
            return list(node.args)
        self.refuse(node)

    def _array(self, node, defined):
        if not (isinstance(node, ast.Name) and node.id in self.params):
            self.refuse(node)

    def _indices(self, node, index, ndim=None):
        if not all(isinstance(i, ast.Constant) and type(i.value) is int and i.value >= 0
                   for i in index) or (ndim is not None and len(index) != ndim):  # fmt: skip
            self.refuse(node)

    def _entry(self, node, defined, store):
        self._array(node.value, defined)
        index = _index(node.slice)
        if store and all(isinstance(i, ast.Slice) and i.lower is None and i.upper is None
                         and i.step is None for i in index):  # fmt: skip
            return "fill"
        self._indices(node, index)
        return "entry"

    def _check_statement(self, stmt, defined):
        if isinstance(stmt, ast.Pass):
            return
        if isinstance(stmt, ast.Expr) and isinstance(stmt.value, ast.Call) and isinstance(
                stmt.value.func, ast.Name) and stmt.value.func.id in ("_set1", "_set2") and (
                self.callee(stmt.value) in ("_set1", "_set2")):  # fmt: skip
            call = stmt.value
            if len(call.args) != _SPECIAL[call.func.id]:
                self.refuse(stmt)
            self._array(call.args[0], defined)
            self._indices(call, call.args[1:-1], int(call.func.id[-1]))
            self._check_expr(call.args[-1], defined)
            return
        if isinstance(stmt, ast.AugAssign) and isinstance(stmt.target, ast.Name) and (
                type(stmt.op) in _INPLACE and stmt.target.id in defined
                and stmt.target.id not in self.params):  # fmt: skip
            self._check_expr(stmt.value, defined)
            return
        if not (isinstance(stmt, ast.Assign) and len(stmt.targets) == 1):
            self.refuse(stmt)
        target, value = stmt.targets[0], stmt.value
        if isinstance(target, ast.Tuple):
            if not (isinstance(value, ast.Tuple) and len(value.elts) == len(target.elts)
                    and all(isinstance(t, ast.Name) for t in target.elts)):  # fmt: skip
                self.refuse(stmt)
            values = value.elts
        else:
            values = [value]
        for v in values:
            self._check_expr(v, defined)
        if isinstance(target, ast.Subscript):
            if self._entry(target, defined, store=True) == "fill" and (
                    self.constant(value) is None and not (
                    isinstance(value, ast.Name) and value.id in defined)):  # fmt: skip
                self.refuse(stmt)
            return
        for t in (target.elts if isinstance(target, ast.Tuple) else [target]):
            if not isinstance(t, ast.Name) or t.id in self.params:
                self.refuse(stmt)
            defined.add(t.id)


class _Walk:
    """What typing and lowering share: the statements, in order, with the names they bind
    (``expr``, ``apply`` an operation to values, ``set_entry`` and ``assign_entry`` are
    each's own)."""

    def statement(self, stmt):
        if isinstance(stmt, ast.Pass):
            return
        if isinstance(stmt, ast.Expr):  # _set1, _set2
            self.set_entry(stmt.value)
            return
        if isinstance(stmt, ast.AugAssign):
            name = stmt.target.id
            self.names[name] = self.apply(stmt, _INPLACE[type(stmt.op)],
                                          (self.names[name], self.expr(stmt.value)))
            return
        target, value = stmt.targets[0], stmt.value
        if isinstance(target, ast.Tuple):
            values = [self.expr(v) for v in value.elts]
            for t, v in zip(target.elts, values):
                self.names[t.id] = v
        elif isinstance(target, ast.Subscript):
            self.assign_entry(target, value)
        else:
            self.names[target.id] = self.expr(value)

    def expr(self, root):
        """The value of an expression, bottom-up: its operands left to right, then the
        operation, as a recursive walk would, with a stack of its own (a generated
        expression may nest thousands deep, past Python's recursion limit)."""
        values: dict = {}
        stack = [(root, False)]
        while stack:
            node, ready = stack.pop()
            if ready:
                values[id(node)] = self.combine(node, [values[id(a)] for a in _operands(node)])
                continue
            value = self.leaf(node)
            if value is not _NOT_LEAF:
                values[id(node)] = value
                continue
            stack.append((node, True))
            stack.extend((a, False) for a in reversed(_operands(node)))
        return values[id(root)]

    def combine(self, node, values):
        """The value of an operator's or a call's node from its operands' ``values``."""
        operation = _operation(node)
        if operation is not None:
            return self.apply(node, operation[0], values)
        return self.call(node, values)


class _Typing(_Walk):
    """The numba types of a :class:`_Function`'s values for given argument types, and the
    signatures of its operations (by node), as numba's type inference would find them."""

    def __init__(self, fn: _Function, typingctx, argtypes):
        self.fn, self.tc = fn, typingctx
        self.names = dict(zip(fn.params, argtypes))
        self.sigs: dict = {}  # id(node) -> numba signature
        for name, t in self.names.items():
            if isinstance(t, types.Array) and t.dtype != types.float64:
                raise _Refused(f"an array of {t.dtype} for {name}")
        for stmt in fn.body:
            self.statement(stmt)
        ret = fn.ret.value if fn.ret is not None else None
        self.restype = types.none if ret is None else types.unliteral(self.expr(ret))
        self.names = None  # only the signatures are kept

    def op(self, node, fn, argtypes):
        sig = _signature(self.tc, fn, tuple(argtypes))
        self.sigs[id(node)] = sig
        return sig.return_type

    def leaf(self, node):
        fn = self.fn
        if isinstance(node, ast.Name) and node.id in self.names:
            return self.names[node.id]
        value = fn.constant(node)
        if value is not None:
            return _constant_type(self.tc, value)
        if isinstance(node, ast.Subscript):
            return self.entry(node.value.id, node.slice)
        if _operation(node) is not None:
            return _NOT_LEAF
        if isinstance(node, ast.Call):
            if fn.callee(node) in ("_at1", "_at2"):
                return self.names[node.args[0].id].dtype
            return _NOT_LEAF
        raise _Refused(_text(node))

    def call(self, node, args):
        callee = self.fn.callee(node)
        if callee in ("fma", "fnma"):
            return types.float64
        if callee in (max, min):  # numba's max of two floats, written out (below)
            if not all(isinstance(a, types.Float) for a in args):
                raise _Refused(f"{_text(node)} of {args}")
            return types.float64
        return self.op(node, callee, args)

    def apply(self, node, fn, values):
        return self.op(node, fn, values)

    def set_entry(self, call):
        self.expr(call.args[-1])

    def assign_entry(self, target, value):
        if not isinstance(_index(target.slice)[0], ast.Slice):
            self.entry(target.value.id, target.slice)
        self.expr(value)

    def entry(self, name, index):
        """The type of ``name[index]``: one of its entries, all its indices given."""
        aryty = self.names[name]
        if len(_index(index)) != aryty.ndim:
            raise _Refused(f"{name}[{ast.unparse(index)}] of a {aryty.ndim}-d array in "
                           f"{self.fn.fn_def.name}: give every index")  # fmt: skip
        return aryty.dtype


class _Lowering(_Walk):
    """A :class:`_Function` written into ``builder`` with its :class:`_Typing`: every
    value a pair ``(numba type, llvm value)``."""

    def __init__(self, fn: _Function, typing: _Typing, context, builder, argtypes, args):
        self.fn, self.sigs, self.context, self.builder = fn, typing.sigs, context, builder
        self.names = {p: (t, v) for p, t, v in zip(fn.params, argtypes, args)}
        # each array's data pointer, shape and strides read once, at the entry (which
        # every use follows), for numba's own pointer arithmetic at each entry
        self.arrays = {}
        for p, t, v in zip(fn.params, argtypes, args):
            if isinstance(t, types.Array):
                array = context.make_array(t)(context, builder, v)
                self.arrays[p] = (array, array.data,
                                  cgutils.unpack_tuple(builder, array.shape, t.ndim),
                                  cgutils.unpack_tuple(builder, array.strides, t.ndim))

    def cast(self, value, to):
        t, v = value
        return self.context.cast(self.builder, v, t, to)

    def call_impl(self, node, fn, args):
        """numba's implementation of ``fn`` at ``node``'s signature, the operands cast to
        its argument types."""
        sig = self.sigs[id(node)]
        impl = _implementation(self.context, fn, sig)
        vals = [self.cast(a, t) for a, t in zip(args, sig.args)]
        return sig.return_type, impl(self.builder, vals)

    def pointer(self, array_node, index):
        aryty = self.names[array_node.id][0]
        _, data, shape, strides = self.arrays[array_node.id]
        idx = [self.context.get_constant(types.intp, i) for i in index]
        return aryty, cgutils.get_item_pointer2(self.context, self.builder, data, shape,
                                                strides, aryty.layout, idx)  # fmt: skip

    def constant(self, value):
        t = _constant_type(self.context.typing_context, value)
        return t, self.context.get_constant(types.unliteral(t), value)

    def leaf(self, node):
        fn, b = self.fn, self.builder
        if isinstance(node, ast.Name) and node.id in self.names:
            return self.names[node.id]
        value = fn.constant(node)
        if value is not None:
            return self.constant(value)
        if isinstance(node, ast.Subscript):
            index = _index(node.slice)
            aryty, ptr = self.pointer(node.value, [i.value for i in index])
            return aryty.dtype, b.load(ptr)
        if _operation(node) is not None:
            return _NOT_LEAF
        if fn.callee(node) in ("_at1", "_at2"):
            aryty, ptr = self.pointer(node.args[0], [i.value for i in node.args[1:]])
            return aryty.dtype, b.load(ptr)
        return _NOT_LEAF

    def call(self, node, args):
        fn, b = self.fn, self.builder
        callee = fn.callee(node)
        if callee in ("fma", "fnma"):
            x, y, z = (self.cast(a, types.float64) for a in args)
            x = b.fneg(x) if callee == "fnma" else x
            if fn.fused:
                return types.float64, b.fma(x, y, z)  # llvm.fma.f64, as :func:`.fma.fma`
            return types.float64, b.fadd(b.fmul(x, y), z)  # as :func:`.fma.fma` without FMA
        if callee in (max, min):
            # numba's max and min of two floats: ``y if y > x else x`` (Python's order)
            x, y = (self.cast(a, types.float64) for a in args)
            pick = b.fcmp_ordered(">" if callee is max else "<", y, x)
            return types.float64, b.select(pick, y, x)
        return self.call_impl(node, callee, args)

    def store(self, target, value):
        index = _index(target.slice)
        aryty = self.names[target.value.id][0]
        array, _, shape, _ = self.arrays[target.value.id]
        v = self.cast(value, aryty.dtype)
        if isinstance(index[0], ast.Slice):  # every entry
            intp = self.context.get_value_type(types.intp)
            with cgutils.loop_nest(self.builder, shape, intp) as idx:
                ptr = cgutils.get_item_pointer(self.context, self.builder, aryty, array, idx)
                self.builder.store(v, ptr)
            return
        _, ptr = self.pointer(target.value, [i.value for i in index])
        self.builder.store(v, ptr)

    def apply(self, node, fn, values):
        return self.call_impl(node, fn, values)

    def set_entry(self, call):
        aryty, ptr = self.pointer(call.args[0], [i.value for i in call.args[1:-1]])
        self.builder.store(self.cast(self.expr(call.args[-1]), aryty.dtype), ptr)

    def assign_entry(self, target, value):
        self.store(target, self.expr(value))


def emitted(fn_def, namespace: dict, label: str, fused: bool = HOST_FMA, params=None):
    """An intrinsic named ``label`` doing what the straight-line function ``fn_def`` does
    with the globals ``namespace`` (see the module docstring for the language); raises
    NotImplementedError for code outside that language.  ``fused``: whether the written-out
    linear algebra's ``fma`` is the fused multiply-add (else ``a * b + c``, as
    :func:`.fma.fma` on a CPU without one).

    ``fn_def`` may instead be a function that returns it, with ``params`` its arguments'
    names: it is then called, and the code checked, when numba first types the intrinsic,
    which a kernel loaded from the cache never does (for code the library writes itself,
    which is in the language by construction; its checks then fail at compile time)."""
    if params is None:
        checked = _Function(fn_def, namespace, fused)
        params = checked.params
        function = lambda: checked  # noqa: E731
    else:
        function = cache(lambda: _Function(fn_def(), namespace, fused))
    typings: dict = {}  # argument types -> _Typing

    def typer(typingctx, *argtypes):
        if len(argtypes) != len(params):
            return None
        fn = function()
        if argtypes not in typings:
            typings[argtypes] = _Typing(fn, typingctx, argtypes)
        typing = typings[argtypes]

        def codegen(context, builder, sig, args):
            lowering = _Lowering(fn, typing, context, builder, sig.args, args)
            for stmt in fn.body:
                lowering.statement(stmt)
            if fn.ret is None or fn.ret.value is None:
                return context.get_dummy_value()
            return lowering.cast(lowering.expr(fn.ret.value), sig.return_type)

        return typing.restype(*argtypes), codegen

    # numba reads the typer's parameters for the intrinsic's (a ``*args`` typer would be
    # called with one tuple): one explicit parameter per argument
    names = ", ".join(params)
    spelled = {"_typer": typer}
    exec(f"def {label}(typingctx, {names}):\n    return _typer(typingctx, {names})\n", spelled)
    return intrinsic(spelled[label])


def emitted_source(pyfunc, label: str):
    """``pyfunc`` (a plain Python function, such as a model's) as an intrinsic of
    :func:`emitted` (called from compiled code only); raises NotImplementedError where its
    code is outside the language, its source cannot be read, or it has free variables."""
    if pyfunc.__code__.co_freevars:
        raise _Refused(f"{pyfunc.__name__} has free variables")
    try:
        source = textwrap.dedent(inspect.getsource(pyfunc))
    except (OSError, TypeError) as exc:
        raise _Refused(f"no source for {pyfunc.__name__}") from exc
    fn_def = ast.parse(source).body[0]
    if not isinstance(fn_def, ast.FunctionDef):
        raise _Refused(f"{pyfunc.__name__} is not a function definition")
    fn_def.decorator_list = []
    return emitted(fn_def, pyfunc.__globals__, label)
