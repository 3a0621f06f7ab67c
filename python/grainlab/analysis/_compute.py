"""A measure's computed results, each declared once (not public API).

``name = Computed[type]("doc")`` on a :class:`Compute` subclass gives the result's
doc (``help()``, the API), its type (mypy) and the :class:`NotComputedError`,
naming the measure and the result, raised before ``compute`` stored it with
:meth:`Compute._store`. The stored record is a frozen dataclass made from the
declarations (the notebook table lists its fields).
"""

from __future__ import annotations

import dataclasses
from typing import Any, ClassVar, Generic, TypeVar, overload

T = TypeVar("T")


class NotComputedError(AttributeError):
    """Raised when a result is read before ``compute`` ran."""


class Computed(Generic[T]):
    """One result of a :class:`Compute` measure, read-only, available after ``compute``."""

    def __init__(self, doc: str) -> None:
        self.__doc__ = doc
        self.name = ""

    def __set_name__(self, owner: type, name: str) -> None:
        self.name = name

    @overload
    def __get__(self, measure: None, owner: type) -> Computed[T]: ...

    @overload
    def __get__(self, measure: Compute, owner: type) -> T: ...

    def __get__(self, measure: Compute | None, owner: type) -> Computed[T] | T:
        if measure is None:
            return self
        value: T = getattr(measure._computed(self.name), self.name)
        return value

    def __set__(self, measure: Compute, value: T) -> None:
        raise AttributeError(f"{type(measure).__name__}.{self.name}: a result is set by compute()")


class Compute:
    """Base of the measures: results declared with :class:`Computed`, stored by ``compute``."""

    #: The record type of the class's results (made from its declarations).
    _record: ClassVar[type]
    #: The constructor's parameters the repr shows, ``"name"`` or ``"name=attribute"``.
    _parameters: ClassVar[tuple[str, ...]] = ()
    _results: Any = None

    def __init_subclass__(cls, **kwargs: Any) -> None:
        super().__init_subclass__(**kwargs)
        names: dict[str, None] = {}
        for klass in reversed(cls.__mro__):
            for name, value in vars(klass).items():
                if isinstance(value, Computed):
                    names[name] = None
        record = dataclasses.make_dataclass(
            f"{cls.__name__}Results", list(names), frozen=True, eq=False
        )
        record.__module__ = cls.__module__  # where pickle finds it
        record.__qualname__ = f"{cls.__qualname__}._record"
        cls._record = record

    def _computed(self, name: str) -> Any:
        """The results record, read for the result ``name`` (named in the error
        raised before ``compute`` ran)."""
        if self._results is None:
            raise NotComputedError(
                f"{type(self).__name__}.{name} is not available: call compute(...) first"
            )
        return self._results

    def _store(self, **results: Any) -> None:
        """Store every declared result (a missing or unknown name is a TypeError)."""
        self._results = self._record(**results)

    def __repr__(self) -> str:
        shown = (p.partition("=") for p in self._parameters)
        args = ", ".join(f"{name}={getattr(self, attr or name)!r}" for name, _, attr in shown)
        return f"{type(self).__name__}({args})"

    def _repr_html_(self) -> str:
        """A small table for notebooks: the repr, the scalar results, the arrays' shapes and means."""
        from grainlab._repr import measure_html

        return measure_html(self)
