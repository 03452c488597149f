"""The type stubs (mlcp/__init__.pyi) name every public function, class, method and property
with the module's own parameters and defaults."""

import ast
import inspect
import pathlib

import mlcp

STUB = pathlib.Path(mlcp.__file__).with_name("__init__.pyi")


def stub_tree():
    tree = ast.parse(STUB.read_text())
    return {node.name: node for node in tree.body
            if isinstance(node, (ast.FunctionDef, ast.ClassDef))}


def stub_params(fn):
    args = fn.args
    names = [a.arg for a in args.args]
    defaults = [ast.literal_eval(d) if not isinstance(d, ast.Name) else d.id
                for d in args.defaults]
    return names, defaults


def runtime_params(fn):
    sig = inspect.signature(fn)
    names = list(sig.parameters)
    defaults = [p.default for p in sig.parameters.values() if p.default is not inspect.Parameter.empty]
    return names, defaults


def test_every_public_name_is_stubbed():
    stubs = stub_tree()
    assert set(mlcp.__all__) <= set(stubs)


def test_function_signatures_match():
    stubs = stub_tree()
    for name in ("solve", "run", "solvers", "engines", "sweep", "stability"):
        assert stub_params(stubs[name]) == runtime_params(getattr(mlcp, name)), name


def test_class_members_match():
    stubs = stub_tree()
    for cls_name in ("Problem", "Result", "Run"):
        cls = getattr(mlcp, cls_name)
        members = {n.name: n for n in stubs[cls_name].body if isinstance(n, ast.FunctionDef)}
        fields = {n.target.id for n in stubs[cls_name].body if isinstance(n, ast.AnnAssign)}
        public = {n for n in dir(cls) if not n.startswith("_")}
        if hasattr(cls, "__dataclass_fields__"):
            public |= set(cls.__dataclass_fields__)
        assert public == (set(members) - {"__init__"}) | fields, cls_name
        for name, node in members.items():
            attr = inspect.getattr_static(cls, name)
            if isinstance(attr, property):
                continue
            fn = getattr(cls, name)
            names, defaults = runtime_params(fn)
            if isinstance(attr, classmethod):
                names = ["cls"] + names
            assert stub_params(node) == (names, defaults), f"{cls_name}.{name}"
