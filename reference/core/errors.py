"""Exceptions of feedoracle.

Every error a user can cause names *where* (file and line, machine-data key, NC block)
and *why* (the rule that was broken). They subclass the built-in that fits, so
``except ValueError`` in user code keeps working. The CLI turns any
:class:`FeedOracleError` into a one-line message and exit code 2, never a traceback.
"""

from __future__ import annotations


class FeedOracleError(Exception):
    """Base class of all feedoracle errors."""


class NCSyntaxError(FeedOracleError, ValueError):
    """A malformed NC program.

    Parameters
    ----------
    file : str
        Program file name as given.
    line : int
        1-based line number.
    column : int
        1-based column of the offending word.
    message : str
        What is wrong, in words a machinist understands.
    """

    def __init__(self, file: str, line: int, column: int, message: str) -> None:
        self.file = file
        self.line = line
        self.column = column
        self.message = message
        super().__init__(f"{file}:{line}:{column}: {message}")


class MachineDataError(FeedOracleError, ValueError):
    """A machine-data key that is unknown, has the wrong type or breaks a rule.

    Parameters
    ----------
    key : str
        Dotted key, e.g. ``"axis.X.MAX_AX_ACCEL"``.
    value : object
        The value found (``None`` when the key is missing).
    rule : str
        The rule that was broken, with units.
    source : str
        File the value came from (``"<default machine>"`` for bundled data).
    """

    def __init__(self, key: str, value: object, rule: str, source: str = "") -> None:
        self.key = key
        self.value = value
        self.rule = rule
        self.source = source
        where = f"{source}: " if source else ""
        super().__init__(f"{where}{key} = {value!r}: {rule}")


class PathError(FeedOracleError, ValueError):
    """A program whose geometry cannot be turned into a path (names the block).

    Parameters
    ----------
    message : str
        Full message, naming the file, line and block.
    block : int
        Index of the offending block, -1 when not tied to one block.
    """

    def __init__(self, message: str, block: int = -1) -> None:
        self.block = block
        super().__init__(message)


class InfeasibleError(FeedOracleError, RuntimeError):
    """A motion problem without a solution (names the block and the limit).

    Parameters
    ----------
    message : str
        Full message, naming the block and the limit.
    block : int
        Index of the offending block, -1 when not tied to one block.
    """

    def __init__(self, message: str, block: int = -1) -> None:
        self.block = block
        super().__init__(message)


class ProfileError(FeedOracleError, ValueError):
    """A profile whose arrays are inconsistent (shapes, NaN, time running backwards)."""


class BackendNotFoundError(FeedOracleError, ImportError):
    """A solver backend whose package is not installed (names what to install)."""


class SolverError(FeedOracleError, RuntimeError):
    """A numerical backend failed in a way that is not a property of the problem."""


class TrajectoryError(FeedOracleError, ValueError):
    """A recorded trajectory (CSV) that cannot be read or projected (names file and row)."""


class InternalError(RuntimeError):
    """An invariant of feedoracle itself failed: a bug, never a property of the input.

    Deliberately *not* a :class:`FeedOracleError`: the CLI reports it with exit code 3
    ("internal error"), so a CI gate never mistakes a crash for bad input or a gap.
    """


class BudgetError(FeedOracleError, ValueError):
    """A program (or machine data) whose evaluation would exceed a stated size budget.

    Raised *before* the large arrays are allocated, naming the cause (the line, the key or
    the option) and the option that raises the budget.
    """
