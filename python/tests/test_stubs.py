"""The type stubs (rccx/*.pyi) match the package: every public name of every module of rccx
(found by walking the package, so new modules are checked as they appear) and every public
method, property and attribute of their classes appears in the module's stub, read with `ast`;
and no stub names a module-level name, class or member that the package does not have.

Stub conventions this follows (PEP 484): a stub's `from x import y as y` and names in its
__all__ are exports, other imports are for annotations only; names starting with `_` (type
aliases such as _ArrayLike) are the stub's own."""

import ast
import dataclasses
import importlib
import inspect
import pathlib
import pkgutil
import re
import types

import pytest

from _support import import_rccx

rccx = import_rccx()

PACKAGE = pathlib.Path(rccx.__file__).resolve().parent
# Names every object has that stubs leave out.
IGNORED_MEMBERS = {"mro"}


def public(name):
    return not name.startswith("_")


def modules():
    """rccx and every module in it but the extension (_rccx)."""
    found = [rccx]
    for info in pkgutil.iter_modules(rccx.__path__):
        if public(info.name):
            found.append(importlib.import_module(f"rccx.{info.name}"))
    return found


def stub_of(module):
    path = PACKAGE / (("__init__" if module is rccx else module.__name__.split(".")[-1]) + ".pyi")
    return path, ast.parse(path.read_text(), filename=str(path))


class StubClass:
    def __init__(self, node, module_stub):
        self.node = node
        self.module_stub = module_stub
        self.members = set()
        for item in node.body:
            if isinstance(item, (ast.FunctionDef, ast.AsyncFunctionDef, ast.ClassDef)):
                self.members.add(item.name)
            elif isinstance(item, ast.AnnAssign) and isinstance(item.target, ast.Name):
                self.members.add(item.target.id)
            elif isinstance(item, ast.Assign):
                self.members.update(t.id for t in item.targets if isinstance(t, ast.Name))
        self.bases = [ast.unparse(b) for b in node.bases]


class ModuleStub:
    """A .pyi file's exports: its classes and functions, assignments, `import y as y`."""

    def __init__(self, module):
        self.module = module
        self.path, tree = stub_of(module)
        self.names = {}  # name -> StubClass, or None for a function / constant / re-export
        self.reexports = {}  # name -> (module, name) it comes from
        self.all = None
        for node in tree.body:
            if isinstance(node, ast.ClassDef):
                self.names[node.name] = StubClass(node, self)
            elif isinstance(node, (ast.FunctionDef, ast.AsyncFunctionDef)):
                self.names[node.name] = None
            elif isinstance(node, ast.AnnAssign) and isinstance(node.target, ast.Name):
                self.names[node.target.id] = None
            elif isinstance(node, ast.Assign):
                for t in node.targets:
                    if isinstance(t, ast.Name) and t.id != "__all__":
                        self.names[t.id] = None
                    elif isinstance(t, ast.Name):
                        self.all = set(ast.literal_eval(node.value))
            elif isinstance(node, ast.AugAssign) and ast.unparse(node.target) == "__all__":
                self.all = (self.all or set()) | set(ast.literal_eval(node.value))
            elif isinstance(node, ast.ImportFrom):
                for a in node.names:
                    if a.asname is not None and a.asname == a.name:
                        self.names[a.name] = None
                        self.reexports[a.name] = (node.module, node.level)
            elif isinstance(node, ast.Import):
                for a in node.names:
                    if a.asname is not None and a.asname == a.name:
                        self.names[a.name] = None

    def exports(self):
        names = {n for n in self.names if public(n)}
        return names | (self.all or set())


STUBS = {m.__name__: ModuleStub(m) for m in modules()}


def stub_class(module_name, name):
    """The StubClass of `name` in a module's stub, following re-exports (`from .motion import
    Arm as Arm`)."""
    stub = STUBS[module_name]
    found = stub.names.get(name)
    if isinstance(found, StubClass):
        return found
    if name in stub.reexports:
        source, level = stub.reexports[name]
        if level == 1:
            target = "rccx." + source if source else "rccx"
            if target in STUBS:
                return stub_class(target, name)
    return None


def stub_members(cls_stub, module_name):
    """A stub class's members with those of its bases in the stubs."""
    members = set(cls_stub.members)
    for base in cls_stub.bases:
        base_stub = stub_class(module_name, base)
        if base_stub is not None:
            members |= stub_members(base_stub, module_name)
    return members


def runtime_public_names(module):
    """__all__ when the module has one, else its public names that are not other modules'
    imports (numpy, typing ...)."""
    if hasattr(module, "__all__"):
        return set(module.__all__)
    names = set()
    for name, value in vars(module).items():
        if not public(name):
            continue
        origin = getattr(value, "__module__", None)
        if isinstance(value, types.ModuleType):
            if value.__name__.startswith("rccx."):
                names.add(name)
        elif origin is None or str(origin).startswith("rccx"):
            names.add(name)
    return names


def ours(cls):
    return str(getattr(cls, "__module__", "")).startswith("rccx")


def instance_attributes(cls):
    """Attributes a Python class's instances get: dataclass fields, __slots__, and
    `self.x = ...` in its methods."""
    names = set()
    for klass in cls.__mro__:
        if not ours(klass):
            continue
        if dataclasses.is_dataclass(klass):
            names.update(f.name for f in dataclasses.fields(klass))
        slots = klass.__dict__.get("__slots__", ())
        names.update([slots] if isinstance(slots, str) else slots)
        try:
            source = inspect.getsource(klass)
        except (OSError, TypeError):
            continue  # a pybind11 class: its members are in dir()
        names.update(re.findall(r"\bself\.([A-Za-z]\w*)\s*(?::[^=\n]+)?=(?!=)", source))
    return names


def runtime_members(cls):
    """Public methods, properties and attributes of an rccx class, without those it inherits
    from Python's or pybind11's own classes (object, Exception, pybind11_object)."""
    foreign = set()
    for klass in cls.__mro__[1:]:
        if not ours(klass):
            foreign |= set(dir(klass))
    names = {n for n in dir(cls) if public(n) and n not in foreign}
    return (names | instance_attributes(cls)) - IGNORED_MEMBERS


def test_every_module_has_a_stub():
    found = [m.__name__ for m in modules()]
    assert {"rccx", "rccx.kin", "rccx.log", "rccx.plot", "rccx.db", "rccx.motion"} <= set(found)
    for name in found:
        assert STUBS[name].path.is_file(), f"{name} has no stub"


@pytest.mark.parametrize("module", modules(), ids=lambda m: m.__name__)
def test_module_names_match_the_stub(module):
    stub = STUBS[module.__name__]
    runtime = runtime_public_names(module)
    exported = stub.exports()
    missing = sorted(runtime - exported)
    assert not missing, f"{stub.path.name} lacks {missing}"
    absent = sorted(n for n in exported if not hasattr(module, n))
    assert not absent, f"{stub.path.name} names what {module.__name__} does not have: {absent}"
    if stub.all is not None and hasattr(module, "__all__"):
        assert stub.all == set(module.__all__), f"{stub.path.name}'s __all__ differs"


def classes_of(module):
    stub = STUBS[module.__name__]
    out = []
    for name in sorted(stub.exports()):
        value = getattr(module, name, None)
        if inspect.isclass(value) and ours(value):
            out.append((module, name, value))
    return out


ALL_CLASSES = [c for m in modules() for c in classes_of(m)]


@pytest.mark.parametrize("module,name,cls", ALL_CLASSES,
                         ids=[f"{m.__name__}.{n}" for m, n, _ in ALL_CLASSES])
def test_class_members_match_the_stub(module, name, cls):
    cls_stub = stub_class(module.__name__, name)
    assert cls_stub is not None, f"{name} is not a class in {STUBS[module.__name__].path.name}"
    in_stub = {n for n in stub_members(cls_stub, module.__name__) if public(n)}
    runtime = runtime_members(cls)
    missing = sorted(runtime - in_stub)
    assert not missing, f"the stub of {module.__name__}.{name} lacks {missing}"
    absent = sorted(n for n in in_stub if n not in runtime and not hasattr(cls, n))
    assert not absent, f"the stub of {module.__name__}.{name} names what it has not: {absent}"


def test_the_check_can_fail():
    # A stub lacking a member, and one naming a member that does not exist, are both found.
    fake = ast.parse("class Robot:\n    def close(self) -> None: ...\n    def fly(self): ...\n")
    cls_stub = StubClass(fake.body[0], None)
    runtime = runtime_members(rccx.Robot)
    assert "move" in runtime - cls_stub.members
    assert "fly" in cls_stub.members - runtime
