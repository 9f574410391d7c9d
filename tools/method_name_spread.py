#!/usr/bin/env python3
"""Where each method's name appears in code outside its own folders (issue 41:
"each method is one folder plus one registry line; a method's name appears in
at most 8 code files outside tests, docs, bench and scenes").

A method is a folder of native/src/methods. Its own folders are
native/src/methods/M, native/include/tempera/methods/M, addon/tempera/methods/M
and addon/tempera/blender/methods/M(.py). The rest of native/, addon/, tools/,
farm/, the Makefile and CMakeLists.txt is searched, case-insensitively, in
code only. Comments, docstrings and prose in strings (a string with a space:
messages and help, which cite the papers) name a method as a reference, not
as coupling, so they do not count; a string without a space does (a name in a
key or a path is how dispatch by name spreads).

    /usr/bin/python3 tools/method_name_spread.py [--files]
"""
import argparse
import ast
import io
import re
import subprocess
import tokenize
from pathlib import Path

ROOT = Path(__file__).resolve().parent.parent
SEARCHED = ("native", "addon", "tools", "farm", "Makefile", "CMakeLists.txt")
PROSE = re.compile(r"\s")  # a string with a space is prose
C_STRING = re.compile(r'"(?:[^"\\\n]|\\.)*"')
HASH_COMMENTS = {".py", ".txt", ".cmake", ""}  # Python is tokenized; CMake and Makefiles drop '#' comments


def methods():
    return sorted(p.name for p in (ROOT / "native" / "src" / "methods").iterdir() if p.is_dir())


def own_folders(method):
    return (f"native/src/methods/{method}/", f"native/include/tempera/methods/{method}/",
            f"addon/tempera/methods/{method}/", f"addon/tempera/blender/methods/{method}/",
            f"addon/tempera/blender/methods/{method}.py")


def python_code(text):
    """The tokens of Python source without its comments and docstrings."""
    try:
        docstrings = {(n.lineno, n.col_offset) for n in ast.walk(ast.parse(text))
                      if isinstance(n, ast.Expr) and isinstance(n.value, ast.Constant) and isinstance(n.value.value, str)}
        tokens = list(tokenize.generate_tokens(io.StringIO(text).readline))
    except (SyntaxError, tokenize.TokenError):
        return text
    return " ".join(t.string for t in tokens if t.type != tokenize.COMMENT
                    and not (t.type == tokenize.STRING and (t.start in docstrings or PROSE.search(t.string))))


def code_text(path):
    """The file's text without its comments (and, for Python, docstrings)."""
    text = path.read_text(errors="replace")
    if path.suffix == ".py":
        return python_code(text)
    if path.suffix in (".cpp", ".hpp", ".h", ".js"):
        text = re.sub(r"/\*.*?\*/", "", text, flags=re.S)
        text = "\n".join(line.split("//")[0] for line in text.splitlines())
        return C_STRING.sub(lambda m: "" if PROSE.search(m.group()) else m.group(), text)
    if path.suffix in HASH_COMMENTS or path.name == "Makefile":
        return "\n".join(line.split("#")[0] for line in text.splitlines())
    return None  # not code (data, images, markdown)


def spread():
    """{method: [file, ...]}: the files outside the method's folders whose code names it."""
    listed = subprocess.run(["git", "ls-files", *SEARCHED], cwd=ROOT, capture_output=True, text=True,
                            check=True).stdout.split()
    texts = {}
    for name in listed:
        if not name.endswith(".md") and (ROOT / name).is_file():
            text = code_text(ROOT / name)
            if text is not None:
                texts[name] = text.lower()
    return {m: [f for f, text in texts.items() if not f.startswith(own_folders(m)) and m in text] for m in methods()}


def main():
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--files", action="store_true", help="list the files")
    args = parser.parse_args()
    for method, files in spread().items():
        print(f"{method}: {len(files)} file(s)")
        if args.files:
            for f in files:
                print(f"    {f}")


if __name__ == "__main__":
    main()
