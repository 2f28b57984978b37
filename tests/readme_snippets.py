"""readme_snippets.py README.md EXAMPLES_DIR

Checks that every code block of the README's section "Use it from your code"
is the examples' code: its lines, dedented, are consecutive lines of one file
under EXAMPLES_DIR (which make examples builds and runs).  Exit 1 naming the
first block that is not, 0 otherwise.
"""
import pathlib
import re
import sys
import textwrap

SECTION = "## Use it from your code"


def blocks(readme):
    text = readme.read_text()
    if SECTION not in text:
        sys.exit(f"readme_snippets: no section '{SECTION}' in {readme}")
    section = text.split(SECTION, 1)[1]
    section = re.split(r"^## ", section, maxsplit=1, flags=re.M)[0]
    return re.findall(r"^```[a-z]*\n(.*?)^```", section, flags=re.M | re.S)


def found_in(block, path):
    want = textwrap.dedent(block).splitlines()
    lines = path.read_text().splitlines()
    for i in range(len(lines) - len(want) + 1):
        if textwrap.dedent("\n".join(lines[i:i + len(want)])).splitlines() == want:
            return True
    return False


def main():
    readme, examples = pathlib.Path(sys.argv[1]), pathlib.Path(sys.argv[2])
    files = [p for p in sorted(examples.rglob("*")) if p.is_file() and p.suffix in (".cpp", ".hpp", ".py", ".txt")]
    found = blocks(readme)
    if not found:
        sys.exit(f"readme_snippets: no code block in the section '{SECTION}'")
    for block in found:
        if not any(found_in(block, p) for p in files):
            first = block.splitlines()[0] if block.strip() else "(empty)"
            sys.exit(f"readme_snippets: a README block is not the examples' code (it starts: {first})")
    print(f"readme_snippets: {len(found)} blocks, each the code of a file in {examples}")


main()
