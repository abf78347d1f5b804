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
