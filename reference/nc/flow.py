"""Control flow: pairing of openers and closers, labels and jumps, NGC O-words.

Conditions and loop counts depend only on program variables (evaluated by
:meth:`~reference.nc.state._Interp.ev`). The interpreter loop
(:func:`reference.nc.interp._execute`) asks these functions where to go next; statements
are addressed by their index in ``ip.stmts``.
"""

from __future__ import annotations

from .lines import Stmt
from .state import _Interp


def _match_blocks(ip: _Interp) -> dict[int, int]:
    """Pair IF/ELSE/ENDIF, WHILE/ENDWHILE, ... (statement index -> partner index)."""
    pairs: dict[int, int] = {}
    stack: list[tuple[str, int]] = []
    openers = {"IF": "ENDIF", "WHILE": "ENDWHILE", "FOR": "ENDFOR", "REPEAT": "UNTIL",
               "LOOP": "ENDLOOP"}
    closers = {v: k for k, v in openers.items()}
    o_stack: list[tuple[str, str, int]] = []
    for i, st in enumerate(ip.stmts):
        k = st.kind
        if k in openers:
            stack.append((k, i))
        elif k == "ELSE":
            if not stack or stack[-1][0] != "IF":
                raise ip.err(st, 1, "ELSE without IF")
            pairs[stack[-1][1]] = i          # IF -> ELSE; ELSE -> ENDIF set below
            stack.append(("ELSE", i))
        elif k in closers:
            want = closers[k]
            if k == "ENDIF" and stack and stack[-1][0] == "ELSE":
                _, e = stack.pop()
                pairs[e] = i
                _, f = stack.pop()
                pairs.setdefault(f, e)
                pairs[i] = f
                continue
            if not stack or stack[-1][0] != want:
                raise ip.err(st, 1, f"{k} without {want}")
            _, f = stack.pop()
            pairs.setdefault(f, i)
            pairs[i] = f
        elif k.startswith("O:"):
            kw = k[2:]
            if kw == "WHILE" and o_stack and o_stack[-1][0] == "DO" and (
                    o_stack[-1][1] == st.target):             # closes "oN do"
                _, _, f = o_stack.pop()
                pairs[f] = i
                pairs[("end", f)] = i  # type: ignore
                pairs[i] = f
            elif kw in ("IF", "WHILE", "DO", "REPEAT", "SUB"):
                o_stack.append((kw, st.target, i))
            elif kw in ("ELSEIF", "ELSE"):
                if not o_stack or o_stack[-1][1] != st.target:
                    raise ip.err(st, 1, f"o{st.target} {kw.lower()} without a matching if")
                pairs.setdefault(o_stack[-1][2], i)
                pairs.setdefault(("chain", o_stack[-1][2]), []).append(i)  # type: ignore
            elif kw in ("ENDIF", "ENDWHILE", "ENDREPEAT", "ENDSUB"):
                if not o_stack or o_stack[-1][1] != st.target:
                    raise ip.err(st, 1, f"o{st.target} {kw.lower()} has no matching opener")
                _, _, f = o_stack.pop()
                pairs.setdefault(f, i)
                pairs[("end", f)] = i  # type: ignore
                pairs[i] = f
    if stack:
        k, i = stack[-1]
        raise ip.err(ip.stmts[i], 1, f"{k} is never closed (missing {openers.get(k, 'ENDIF')})")
    if o_stack:
        kw, name, i = o_stack[-1]
        raise ip.err(ip.stmts[i], 1, f"o{name} {kw.lower()} is never closed")
    return pairs


def _labels(ip: _Interp) -> dict[str, list[int]]:
    out: dict[str, list[int]] = {}
    for i, st in enumerate(ip.stmts):
        if st.label:
            out.setdefault(st.label, []).append(i)
    return out


class _LazyLabels:
    """Label -> statement indices, built at the first jump (most programs never jump)."""

    __slots__ = ("ip", "table")

    def __init__(self, ip: _Interp) -> None:
        self.ip = ip
        self.table: dict[str, list[int]] | None = None

    def get(self, key: str, default: list[int]) -> list[int]:
        if self.table is None:
            self.table = _labels(self.ip)
        return self.table.get(key, default)


def _jump(ip: _Interp, st: Stmt, i: int, kind: str, target: str,
          labels: dict[str, list[int]]) -> int | None:
    cands = labels.get(target, [])
    fwd = [j for j in cands if j > i]
    back = [j for j in cands if j < i]
    if kind == "GOTOF":
        j = fwd[0] if fwd else None
    elif kind == "GOTOB":
        j = back[-1] if back else None
    else:                                   # GOTO, GOTOC: forward first, then backward
        j = fwd[0] if fwd else (back[-1] if back else None)
    if j is None and kind != "GOTOC":
        where = {"GOTOF": "after", "GOTOB": "before"}.get(kind, "in")
        raise ip.err(st, 1, f"{kind} {target}: no label {target} {where} this line")
    return j


def _oword(ip: _Interp, st: Stmt, i: int, pairs: dict, subs: dict, calls: list) -> int:
    kw = st.kind[2:]
    if kw == "SUB":
        return pairs[("end", i)] + 1          # skip the definition
    if kw in ("ENDSUB", "RETURN"):
        if not calls:
            if kw == "RETURN":
                raise ip.err(st, 1, f"o{st.target} return outside a subroutine call")
            return i + 1
        ret, saved = calls.pop()
        for p in range(1, 31):
            ip.vars.pop(f"#{p}", None)
        ip.vars.update(saved)
        return ret
    if kw == "CALL":
        if st.target not in subs:
            raise ip.err(st, 1, f"o{st.target} call: no subroutine o{st.target} in this file")
        saved = {f"#{p}": ip.vars[f"#{p}"] for p in range(1, 31) if f"#{p}" in ip.vars}
        args = [ip.ev(st, a) for a in st.case]
        for p in range(1, 31):
            ip.vars.pop(f"#{p}", None)
        for p, v in enumerate(args, start=1):
            ip.vars[f"#{p}"] = v
        calls.append((i + 1, saved))
        return subs[st.target] + 1
    if kw == "IF" or kw == "ELSEIF":
        if kw == "ELSEIF":                      # reached from a taken branch: skip to endif
            return _o_endif(ip, i, pairs) + 1
        branch = i
        while True:
            s = ip.stmts[branch]
            if s.kind in ("O:IF", "O:ELSEIF") and ip.ev(s, s.cond):
                return branch + 1
            if s.kind == "O:ELSE":
                return branch + 1
            nxt = _o_next_branch(ip, branch)
            if nxt is None:
                return _o_endif(ip, i, pairs) + 1
            branch = nxt
    if kw == "ELSE":
        return _o_endif(ip, i, pairs) + 1
    if kw in ("ENDIF", "ENDREPEAT"):
        if kw == "ENDREPEAT":
            f = pairs[i]
            ip.vars[f"__rep{f}"] -= 1
            return f + 1 if ip.vars[f"__rep{f}"] > 0 else i + 1
        return i + 1
    if kw == "WHILE":
        if ("end", i) in pairs or i in pairs and pairs[i] > i:  # while ... endwhile opener
            return i + 1 if ip.ev(st, st.cond) else pairs[("end", i)] + 1
        return pairs[i] if ip.ev(st, st.cond) else i + 1     # do ... while closer
    if kw == "ENDWHILE":
        return pairs[i]
    if kw == "DO":
        return i + 1
    if kw == "REPEAT":
        cnt = ip.ev(st, st.cond)
        ip.vars[f"__rep{i}"] = cnt
        return i + 1 if cnt > 0 else pairs[("end", i)] + 1
    if kw in ("BREAK", "CONTINUE"):
        # find the innermost enclosing loop with this name
        for f, e in ((k[1], v) for k, v in pairs.items() if isinstance(k, tuple) and k[0] == "end"):
            if ip.stmts[f].target == st.target and f < i < e:
                return e + 1 if kw == "BREAK" else f
        raise ip.err(st, 1, f"o{st.target} {kw.lower()} outside a loop")
    return i + 1


def _o_scan(ip: _Interp, i: int, stop_at_branch: bool) -> int | None:
    """From the o-if (or a branch) at ``i``: index of the next same-level elseif/else
    (when ``stop_at_branch``; None if the endif comes first) or of the matching endif."""
    name = ip.stmts[i].target
    depth = 0
    for j in range(i + 1, len(ip.stmts)):
        s = ip.stmts[j]
        if s.target != name:
            continue
        if s.kind == "O:IF":
            depth += 1
        elif s.kind == "O:ENDIF":
            if depth == 0:
                return None if stop_at_branch else j
            depth -= 1
        elif stop_at_branch and s.kind in ("O:ELSEIF", "O:ELSE") and depth == 0:
            return j
    raise ip.err(ip.stmts[i], 1, f"o{name} if is never closed")  # pragma: no cover


def _o_next_branch(ip: _Interp, i: int) -> int | None:
    return _o_scan(ip, i, True)


def _o_endif(ip: _Interp, i: int, pairs: dict) -> int:
    return _o_scan(ip, i, False)
