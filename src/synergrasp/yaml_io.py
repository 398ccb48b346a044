"""The one way the project reads YAML: configuration overlays, scenario maps, hand files,
synergy mapping files and the schema all go through :func:`read_yaml`.

A key that appears twice in one mapping is an error naming the file, the line and the key
(plain YAML keeps the last value without a word). Unreadable files and invalid YAML are
errors naming the file too. This module imports nothing of the project (lowest layer).
"""

from __future__ import annotations

from pathlib import Path
from typing import Any

import yaml

__all__ = ["YamlFileError", "read_yaml", "duplicate_keys"]

#: The C parser where PyYAML has it (about 5× faster on the sensitivity sweep), else Python's.
_Loader = getattr(yaml, "CSafeLoader", yaml.SafeLoader)


class YamlFileError(ValueError):
    """A YAML file cannot be read, is not valid YAML, or repeats a key (one line)."""


def _key_path(path: tuple[str, ...]) -> str:
    return ".".join(path) if path else "<top level>"


def duplicate_keys(node: yaml.Node, path: tuple[str, ...] = ()) -> list[str]:
    """Every key of a composed YAML node that appears twice in one mapping, as one line each
    (the key's path, its line and the line of its first appearance; lines 1-based)."""
    problems: list[str] = []
    if isinstance(node, yaml.MappingNode):
        seen: dict[tuple[str, str], int] = {}
        for key, value in node.value:
            name = str(key.value) if isinstance(key, yaml.ScalarNode) else None
            if name is not None:
                ident = (key.tag, name)
                line = key.start_mark.line + 1
                if ident in seen and name != "<<":
                    problems.append(
                        f"line {line}: key '{_key_path((*path, name))}' appears twice "
                        f"(first at line {seen[ident]}); each key may appear once"
                    )
                seen.setdefault(ident, line)
            problems += duplicate_keys(value, (*path, name if name is not None else "?"))
    elif isinstance(node, yaml.SequenceNode):
        for i, item in enumerate(node.value):
            problems += duplicate_keys(item, (*path[:-1], f"{path[-1]}[{i}]") if path else (f"[{i}]",))
    return problems


def read_yaml(path: str | Path, what: str = "YAML file") -> Any:
    """The content of the YAML file ``path`` (None for an empty file).

    Raises
    ------
    YamlFileError
        naming ``what`` and the path: the file cannot be read, is not valid YAML, or a
        mapping repeats a key (every repeated key is listed, one line each).
    """
    where = f"{what} '{path}'"
    if Path(path).is_dir():
        raise YamlFileError(f"{where}: cannot be read: is a folder; give a file")
    try:
        text = Path(path).read_text(encoding="utf-8")
    except OSError as err:
        raise YamlFileError(f"{where}: cannot be read ({err.strerror or err})") from None
    except UnicodeDecodeError as err:
        raise YamlFileError(f"{where}: not a readable YAML file (not UTF-8 text: {err.reason})") from None
    loader = _Loader(text)
    try:
        node = loader.get_single_node()
        if node is None:
            return None
        problems = duplicate_keys(node)
        if problems:
            raise YamlFileError("\n".join(f"{where}, {p}" for p in problems))
        return loader.construct_document(node)
    except yaml.YAMLError as err:
        raise YamlFileError(f"{where}: not a readable YAML file ({' '.join(str(err).split())})") from None
    finally:
        loader.dispose()
