#!/usr/bin/python3
"""Lists the files in codec/src over 600 lines and the functions (lambdas included) over 80.

A report, not a gate: it always exits 0 once it has run, so each owner can act on what it lists.
Functions are found by clang's parser (libclang, Debian's python3-clang-14, installed by
tools/install-deps.sh) over the compile commands of a configured build, so their extents are
the compiler's, not a guess. Debian's interpreter (/usr/bin/python3) is the one that sees the
package. A function defined in a header is counted once, from the first translation unit that
includes it.

Usage: tools/check-sizes.py [--build DIR] [--jobs N] [--max-file-lines N] [--max-function-lines N]
  DIR holds compile_commands.json (default build/, as `cmake --preset release` configures;
  configuring is enough, nothing needs to be built).
"""

import argparse
import json
import multiprocessing
import os
import shlex
import sys

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
SOURCE_DIR = os.path.join(ROOT, "codec", "src")
SOURCE_SUFFIXES = (".cpp", ".cc", ".h", ".hpp", ".inl")

try:
    import clang.cindex as cindex
except ImportError:
    sys.exit("check-sizes: no libclang Python module; install python3-clang-14 "
             "(tools/install-deps.sh) and run this with /usr/bin/python3")

FUNCTION_KINDS = {
    cindex.CursorKind.FUNCTION_DECL,
    cindex.CursorKind.CXX_METHOD,
    cindex.CursorKind.CONSTRUCTOR,
    cindex.CursorKind.DESTRUCTOR,
    cindex.CursorKind.CONVERSION_FUNCTION,
    cindex.CursorKind.FUNCTION_TEMPLATE,
}


def in_source_dir(path):
    return path is not None and os.path.abspath(path).startswith(SOURCE_DIR + os.sep)


def line_count(path):
    with open(path, "rb") as f:
        return sum(1 for _ in f)


def compiler_arguments(entry):
    """The flags of a compile_commands.json entry, without the compiler, -c, -o and the source."""
    words = entry["arguments"] if "arguments" in entry else shlex.split(entry["command"])
    source = os.path.normpath(os.path.join(entry["directory"], entry["file"]))
    flags = []
    skip_next = False
    for word in words[1:]:
        if skip_next:
            skip_next = False
        elif word == "-o":
            skip_next = True
        elif word == "-c" or os.path.normpath(os.path.join(entry["directory"], word)) == source:
            continue
        else:
            flags.append(word)
    return flags


def qualified_name(cursor):
    parts = []
    while cursor is not None and cursor.kind != cindex.CursorKind.TRANSLATION_UNIT:
        parts.append(cursor.spelling or "(anonymous)")
        cursor = cursor.semantic_parent
    return "::".join(reversed(parts))


def function_spans(entry):
    """(file, first line, lines, name) of every function or lambda body from codec/src in one TU."""
    source = entry["file"]
    index = cindex.Index.create()
    try:
        unit = index.parse(source, args=compiler_arguments(entry),
                           options=cindex.TranslationUnit.PARSE_INCOMPLETE)
    except cindex.TranslationUnitLoadError as error:
        return source, [], [f"cannot parse: {error}"]
    errors = [str(d) for d in unit.diagnostics if d.severity >= cindex.Diagnostic.Error]
    spans = []

    def visit(cursor, enclosing):
        for child in cursor.get_children():
            location = child.location.file
            if location is None or not in_source_dir(location.name):
                continue
            if child.kind in FUNCTION_KINDS and child.is_definition():
                name = qualified_name(child)
            elif child.kind == cindex.CursorKind.LAMBDA_EXPR:
                name = f"lambda in {enclosing}" if enclosing else "lambda"
            else:
                visit(child, enclosing)
                continue
            start, end = child.extent.start.line, child.extent.end.line
            spans.append((os.path.relpath(location.name, ROOT), start, end - start + 1, name))
            visit(child, name)

    visit(unit.cursor, None)
    return source, spans, errors


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--build", default=os.path.join(ROOT, "build"))
    parser.add_argument("--jobs", type=int, default=os.cpu_count())
    parser.add_argument("--max-file-lines", type=int, default=600)
    parser.add_argument("--max-function-lines", type=int, default=80)
    options = parser.parse_args()

    database = os.path.join(options.build, "compile_commands.json")
    if not os.path.isfile(database):
        sys.exit(f"check-sizes: no {database}; configure first (cmake --preset release)")
    with open(database) as f:
        entries = [e for e in json.load(f) if in_source_dir(e["file"])]
    # One entry per source: a file compiled into two targets has the same functions in both.
    entries = list({os.path.abspath(e["file"]): e for e in entries}.values())

    sources = sorted(os.path.join(d, name) for d, _, names in os.walk(SOURCE_DIR)
                     for name in names if name.endswith(SOURCE_SUFFIXES))
    long_files = sorted(((line_count(p), os.path.relpath(p, ROOT)) for p in sources),
                        reverse=True)
    print(f"check-sizes: files in codec/src over {options.max_file_lines} lines")
    for lines, path in long_files:
        if lines > options.max_file_lines:
            print(f"  {lines:5d}  {path}")

    functions = {}
    unparsed = []
    with multiprocessing.Pool(max(1, options.jobs)) as pool:
        for source, spans, errors in pool.imap_unordered(function_spans, entries):
            if errors:
                unparsed.append((os.path.relpath(source, ROOT), errors[0]))
            for path, start, lines, name in spans:
                functions.setdefault((path, start, name), lines)
    print(f"check-sizes: functions in codec/src over {options.max_function_lines} lines "
          f"({len(entries)} translation units parsed)")
    for (path, start, name), lines in sorted(functions.items(), key=lambda item: -item[1]):
        if lines > options.max_function_lines:
            print(f"  {lines:5d}  {path}:{start}  {name}")
    for path, error in sorted(unparsed):
        print(f"check-sizes: {path} parsed with errors, its extents may be short: {error}")


if __name__ == "__main__":
    main()
