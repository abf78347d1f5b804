"""The package itself: public names, docstrings, exceptions, typing marker."""

import importlib.resources
import inspect

import hrm
import hrm.fuzzy


def public_names():
    for module in (hrm, hrm.fuzzy):
        for name in module.__all__:
            obj = getattr(module, name)
            if inspect.ismodule(obj) or isinstance(obj, str):
                continue
            yield f"{module.__name__}.{name}", obj
            if inspect.isclass(obj) and not issubclass(obj, Exception):
                for member, value in vars(obj).items():
                    if not member.startswith("_"):
                        yield f"{module.__name__}.{name}.{member}", value


def test_every_public_name_has_a_docstring():
    missing = [name for name, obj in public_names() if not (getattr(obj, "__doc__", None) or "").strip()]
    assert missing == []


def test_exceptions():
    assert issubclass(hrm.InvalidInput, ValueError)
    assert issubclass(hrm.Unreachable, ValueError)
    assert issubclass(hrm.NumericalError, ArithmeticError)
    assert not issubclass(hrm.Unreachable, hrm.InvalidInput)


def test_typed_package_and_version():
    files = importlib.resources.files("hrm")
    assert (files / "py.typed").is_file()
    assert (files / "_hrm.pyi").is_file()
    assert hrm.__version__.count(".") == 2
    assert hrm.Arm.__module__ == "hrm" and hrm.fuzzy.System.__module__ == "hrm.fuzzy"


def stub_members(path):
    """Per class of a stub file, the names it declares (methods, properties, attributes)."""
    import ast

    tree = ast.parse(path.read_text())
    classes = {}
    for node in tree.body:
        if isinstance(node, ast.ClassDef):
            names = set()
            for item in node.body:
                if isinstance(item, (ast.FunctionDef, ast.AsyncFunctionDef)):
                    names.add(item.name)
                elif isinstance(item, ast.AnnAssign) and isinstance(item.target, ast.Name):
                    names.add(item.target.id)
            classes[node.name] = names
    return classes


def test_the_stubs_declare_what_the_classes_have():
    # Every public method or property of a class is in _hrm.pyi, and every name the stub declares
    # exists at run time (Scenario's tables are instance attributes: read on a shipped one).
    files = importlib.resources.files("hrm")
    stubs = stub_members(files / "_hrm.pyi")
    scenario = hrm.Scenario.builtin("narrow-gap")
    for name, declared in stubs.items():
        cls = getattr(hrm, name)
        if issubclass(cls, Exception):
            continue
        public = {m for m in vars(cls) if not m.startswith("_")}
        assert public - declared == set(), f"{name}: not in the stub"
        instance = scenario if name == "Scenario" else cls
        # Dunder methods of a stub may be typing devices (Settings' __getattr__ types its keys).
        only = {m for m in declared if not m.startswith("__") and not hasattr(instance, m)}
        assert only == set(), f"{name}: in the stub only"
