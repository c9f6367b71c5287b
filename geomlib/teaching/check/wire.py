"""Plain data between the grading judge and its sandbox: frames of JSON, never pickle.

What the student's function returns is decoded by the judge, which holds the check: so
nothing from the sandbox is unpickled or evaluated. ``encode`` turns numbers, strings,
numpy arrays (dtype, shape and bytes), scipy sparse matrices (their CSR components),
sympy expressions (their ``srepr``), tuples, lists and dicts into JSON-ready data;
``decode`` rebuilds them, sympy through ``parse_srepr``, which only calls sympy's own
classes on literals. Anything else arrives as an opaque ``Foreign`` object carrying its
type's name, so a check says "returned Trimesh" as it would in the kernel.

A frame is a 4-byte big-endian length and that many bytes of UTF-8 JSON.
"""

import ast
import base64
import json
import os
import struct
import types

import numpy as np
import scipy.sparse as sp


class Foreign:
    """A value the wire does not carry (an object of another library), named by its type."""

    def __init__(self, text):
        self.text = text

    def __repr__(self):
        return self.text


def encode(x, callables=None):
    """JSON-ready data for ``x`` (module docstring). A function in ``x`` (a check hands the
    learner's function one, as ``forms`` in 02) is appended to ``callables`` and sent as its
    index: the other side calls it back through ``decode``'s ``callback``."""
    if x is None or type(x) in (bool, int, float, str):
        return x
    if isinstance(x, (bool, int, float, str, complex, np.generic)):
        return {"array": _array(np.asarray(x)), "scalar": True}
    if isinstance(x, np.ndarray):
        if x.dtype == object:
            return {"objects": [encode(v, callables) for v in x.ravel().tolist()], "shape": list(x.shape)}
        return {"array": _array(x)}
    if sp.issparse(x):
        A = x.tocsr()
        return {
            "sparse": x.format,
            "matrix": isinstance(x, sp.spmatrix),
            "shape": list(A.shape),
            "parts": [_array(A.data), _array(A.indices), _array(A.indptr)],
        }
    if isinstance(x, (tuple, list)):
        return {type(x).__name__: [encode(v, callables) for v in x]}
    if isinstance(x, dict):
        return {"dict": [[encode(k, callables), encode(v, callables)] for k, v in x.items()]}
    sympy = _sympy_if_loaded()
    if sympy is not None and isinstance(x, (sympy.Basic, sympy.MatrixBase)):
        return {"sympy": sympy.srepr(x)}
    if callables is not None and isinstance(x, (types.FunctionType, types.MethodType)):
        callables.append(x)
        return {"callable": len(callables) - 1}
    return {"foreign": type(x).__name__}


def _array(a):
    a = np.array(a, order="C")
    if a.dtype.kind not in "biufc":
        a = a.astype(str) if a.dtype.kind in "SU" else a.astype(float)
    return {"dtype": a.dtype.str, "shape": list(a.shape), "bytes": base64.b64encode(a.tobytes()).decode()}


def _unarray(d):
    dtype = np.dtype(d["dtype"])
    if dtype.kind not in "biufcU":
        raise ValueError(f"dtype {d['dtype']} is not carried")
    return np.frombuffer(base64.b64decode(d["bytes"]), dtype=dtype).reshape(d["shape"]).copy()


def _sympy_if_loaded():
    import sys

    return sys.modules.get("sympy")


def decode(d, callback=None):
    """The value ``encode`` made ``d`` from (module docstring); ``callback(index)`` stands in for a
    function sent by its index."""
    if d is None or isinstance(d, (bool, int, float, str)):
        return d
    if "array" in d:
        a = _unarray(d["array"])
        return a[()] if d.get("scalar") else a
    if "objects" in d:
        out = np.empty(len(d["objects"]), dtype=object)
        out[:] = [decode(v, callback) for v in d["objects"]]
        return out.reshape(d["shape"])
    if "sparse" in d:
        data, indices, indptr = (_unarray(p) for p in d["parts"])
        A = (sp.csr_matrix if d["matrix"] else sp.csr_array)((data, indices, indptr), shape=tuple(d["shape"]))
        return A.asformat(d["sparse"])
    if "tuple" in d:
        return tuple(decode(v, callback) for v in d["tuple"])
    if "list" in d:
        return [decode(v, callback) for v in d["list"]]
    if "dict" in d:
        return {decode(k, callback): decode(v, callback) for k, v in d["dict"]}
    if "callable" in d and callback is not None:
        return callback(int(d["callable"]))
    if "sympy" in d:
        return parse_srepr(d["sympy"])
    return Foreign(str(d.get("foreign", "object")))


def parse_srepr(text):
    """A sympy object from its ``srepr``, built only from sympy's classes and literals (no eval)."""
    import sympy

    def build(node):
        if isinstance(node, ast.Constant) and isinstance(node.value, (int, float, str, bool, type(None))):
            return node.value
        if isinstance(node, ast.UnaryOp) and isinstance(node.op, ast.USub):
            return -build(node.operand)
        if isinstance(node, (ast.List, ast.Tuple)):
            items = [build(e) for e in node.elts]
            return items if isinstance(node, ast.List) else tuple(items)
        if isinstance(node, ast.Call) and isinstance(node.func, ast.Name):
            cls = getattr(sympy, node.func.id, None)
            if not (isinstance(cls, type) and issubclass(cls, (sympy.Basic, sympy.MatrixBase))):
                raise ValueError(f"{node.func.id} is not a sympy class")
            return cls(*(build(a) for a in node.args), **{k.arg: build(k.value) for k in node.keywords})
        raise ValueError(f"not an srepr: {ast.dump(node)[:80]}")

    return build(ast.parse(text, mode="eval").body)


def send(fd, message, write=os.write):
    """Write one frame (a JSON-ready ``message``) to the file descriptor ``fd``."""
    data = json.dumps(message).encode()
    data = struct.pack(">I", len(data)) + data
    while data:
        data = data[write(fd, data) :]


def receive(fd, read=os.read):
    """Read one frame from ``fd``: its message, or None at the end of the stream."""
    head = _exactly(fd, 4, read)
    if head is None:
        return None
    body = _exactly(fd, struct.unpack(">I", head)[0], read)
    if body is None:
        return None
    return json.loads(body)


def _exactly(fd, n, read):
    chunks, left = [], n
    while left:
        chunk = read(fd, left)
        if not chunk:
            return None
        chunks.append(chunk)
        left -= len(chunk)
    return b"".join(chunks)
