"""Set fields of a case file (text-format protobuf) by dotted path, without a protobuf runtime.

Only what the sweeps need: a scalar field directly inside a top-level block (`fluid.cfl`,
`coupling.scheme`, `run.end_time`, `solid.density`), or a whole top-level block replaced.
The programs' own loader checks the result (`coupler --describe-launch`), so a misspelt field
is reported there with the file, field and value.
"""
from __future__ import annotations

import re


def format_value(value) -> str:
    """Text-format literal: bool -> true/false, number -> shortest exact-enough, an UPPER_CASE
    word -> enum name, other strings quoted."""
    if isinstance(value, bool):
        return "true" if value else "false"
    if isinstance(value, int):
        return str(value)
    if isinstance(value, float):
        return f"{value:.10g}"
    text = str(value)
    if re.fullmatch(r"[A-Z][A-Z0-9_]*", text):
        return text
    return '"' + text.replace("\\", "\\\\").replace('"', '\\"') + '"'


def block_span(text: str, block: str) -> tuple[int, int] | None:
    """(start of the block's first inner line, start of its closing '}' line) of the top-level
    block `block { ... }` written one field per line, as the generators write them; None if absent."""
    opening = re.search(rf"^{re.escape(block)} {{[ \t]*\n", text, flags=re.MULTILINE)
    if not opening:
        return None
    closing = re.search(r"^\}[ \t]*$", text[opening.end():], flags=re.MULTILINE)
    if not closing:
        raise ValueError(f"case text: block '{block}' has no closing '}}' at the start of a line")
    return opening.end(), opening.end() + closing.start()


def set_field(text: str, path: str, value) -> str:
    """Returns `text` with `block.field: value` set (replaced, or added at the block's end; the
    block is appended when the case has none)."""
    parts = path.split(".")
    if len(parts) != 2 or not all(re.fullmatch(r"[a-z_][a-z0-9_]*", p) for p in parts):
        raise ValueError(f"case field '{path}': allowed 'block.field' (a scalar directly inside a top-level block)")
    block, field = parts
    line = f"  {field}: {format_value(value)}\n"
    span = block_span(text, block)
    if span is None:
        return text.rstrip("\n") + f"\n{block} {{\n{line}}}\n"
    start, end = span
    inner = text[start:end]
    pattern = re.compile(rf"^  {re.escape(field)}:[^\n]*\n", flags=re.MULTILINE)
    if pattern.search(inner):
        inner = pattern.sub(lambda _m: line, inner, count=1)
    else:
        inner = inner + line
    return text[:start] + inner + text[end:]


def get_field(text: str, path: str) -> str | None:
    """The literal of `block.field` as written, or None."""
    block, field = path.split(".")
    span = block_span(text, block)
    if span is None:
        return None
    match = re.search(rf"^  {re.escape(field)}:\s*([^\n#]*?)\s*(#.*)?$", text[span[0]:span[1]], flags=re.MULTILINE)
    return match.group(1) if match else None


def replace_block(text: str, block: str, new_block: str) -> str:
    """Replaces the whole top-level block (including its braces) by `new_block`."""
    span = block_span(text, block)
    if span is None:
        raise ValueError(f"case text: no top-level block '{block}' to replace")
    head = text.rfind("\n", 0, span[0] - 1) + 1
    tail = text.find("\n", span[1])
    tail = len(text) if tail < 0 else tail + 1
    return text[:head] + new_block.rstrip("\n") + "\n" + text[tail:]
