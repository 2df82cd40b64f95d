#!/usr/bin/env python3
"""Checks the links of README.md and docs/**/*.md.

Every relative link and image must name a file or folder inside the
repository, and every #anchor (same page, or page.md#anchor) must name a
heading of the target page, slugged as GitHub slugs headings, or an
explicit <a id="..."> / <a name="..."> anchor. http(s), mailto and ftp links
and everything inside fenced code blocks and inline code are skipped.
README.md must stay within README_LIMIT_BYTES.

    check_links.py [ROOT]      check ROOT (default: the repository)
    check_links.py --self-test check that broken links and anchors are found

Prints one line per problem, "file:line: link: problem", and exits 1 when
there is any.
"""

import os
import re
import subprocess
import sys
import tempfile
import urllib.parse

README_LIMIT_BYTES = 25000

FENCE = re.compile(r"^[ \t]*(`{3,}|~{3,})")
ATX_HEADING = re.compile(r"^ {0,3}(#{1,6})(?:[ \t]+(.*?))?(?:[ \t]+#+)?[ \t]*$")
SETEXT_UNDERLINE = re.compile(r"^ {0,3}(=+|-+)[ \t]*$")
EXPLICIT_ANCHOR = re.compile(r"<a\s[^>]*?\b(?:id|name)\s*=\s*[\"']([^\"']+)[\"']", re.IGNORECASE)
HTML_LINK = re.compile(r"<(?:a|img)\s[^>]*?\b(?:href|src)\s*=\s*[\"']([^\"']+)[\"']", re.IGNORECASE)
REFERENCE_DEFINITION = re.compile(r"^ {0,3}\[[^\]]+\]:\s*(<[^>]*>|\S+)")
EXTERNAL = re.compile(r"^(?:https?:|mailto:|ftp:)", re.IGNORECASE)
SCHEME = re.compile(r"^[A-Za-z][A-Za-z0-9+.-]*:")


def strip_code_spans(text):
    """The text with every inline code span blanked (same length, newlines kept).

    A span opens and closes with backtick runs of the same length and never
    crosses a blank line.
    """
    out = list(text)
    for paragraph in re.finditer(r"(?:[^\n]|\n(?![ \t]*\n))+", text):
        runs = [(m.start(), m.end()) for m in re.finditer(r"`+", paragraph.group(0))]
        base = paragraph.start()
        k = 0
        while k < len(runs):
            start, end = runs[k]
            for j in range(k + 1, len(runs)):
                if runs[j][1] - runs[j][0] == end - start:
                    for p in range(base + start, base + runs[j][1]):
                        if out[p] != "\n":
                            out[p] = " "
                    k = j + 1
                    break
            else:
                k += 1
    return "".join(out)


def prose_lines(text):
    """(line number, line) for every line outside fenced code blocks."""
    fence = None
    for number, line in enumerate(text.split("\n"), start=1):
        m = FENCE.match(line)
        if fence is None:
            if m:
                fence = m.group(1)
                continue
            yield number, line
        elif m and m.group(1)[0] == fence[0] and len(m.group(1)) >= len(fence) and \
                line.strip() == m.group(1):
            fence = None


def prose_text(text):
    """The text with fenced code blocks emptied (line numbers kept) and code spans blanked."""
    lines = [""] * (text.count("\n") + 1)
    for number, line in prose_lines(text):
        lines[number - 1] = line
    return strip_code_spans("\n".join(lines))


def heading_text(raw):
    """The text GitHub slugs: code spans keep their text, links their label, tags go."""
    text = re.sub(r"`+([^`]*)`+", r"\1", raw)
    text = re.sub(r"!?\[([^\]]*)\]\([^)]*\)", r"\1", text)
    text = re.sub(r"<[^>]+>", "", text)
    return text.strip()


def slug_of(text):
    """GitHub's heading slug: lowercase, only letters, digits, spaces, '-' and '_', spaces to '-'."""
    text = text.lower()
    text = "".join(c for c in text if c.isalnum() or c in " -_")
    return text.replace(" ", "-")


def anchors_of(text):
    """Every anchor a page defines: its headings' slugs (with -1, -2 ... for repeats) and <a id/name>."""
    anchors = set()
    occurrences = {}

    def add_heading(raw):
        base = slug_of(heading_text(raw))
        slug = base
        while slug in occurrences:
            occurrences[base] += 1
            slug = "%s-%d" % (base, occurrences[base])
        occurrences[slug] = 0
        anchors.add(slug)

    previous = None  # the previous prose line, when it could start a setext heading
    for _, line in prose_lines(text):
        for m in EXPLICIT_ANCHOR.finditer(line):
            anchors.add(m.group(1))
        m = ATX_HEADING.match(line)
        if m:
            add_heading(m.group(2) or "")
            previous = None
            continue
        if previous is not None and SETEXT_UNDERLINE.match(line):
            add_heading(previous)
            previous = None
            continue
        stripped = line.strip()
        paragraph = stripped and not re.match(r"^(?:[-*+>|]|\d+[.)]\s|<)", stripped) and not line.startswith("    ")
        previous = stripped if paragraph else None
    return anchors


def link_destination(text, start):
    """The destination of an inline link whose '(' is at text[start], or None."""
    i = start + 1
    while i < len(text) and text[i] in " \t":
        i += 1
    if i < len(text) and text[i] == "<":
        end = text.find(">", i)
        return None if end == -1 else text[i + 1:end]
    depth = 0
    j = i
    while j < len(text):
        c = text[j]
        if c == "\\":
            j += 2
            continue
        if c == "(":
            depth += 1
        elif c == ")":
            if depth == 0:
                break
            depth -= 1
        elif c in " \t":
            break
        j += 1
    else:
        return None
    return text[i:j]


def links_of(text):
    """(line number, destination) for every link and image outside code."""
    found = []
    for number, prose in enumerate(prose_text(text).split("\n"), start=1):
        m = REFERENCE_DEFINITION.match(prose)
        if m:
            found.append((number, m.group(1).strip("<>")))
            continue
        for m in re.finditer(r"\]\(", prose):
            destination = link_destination(prose, m.end() - 1)
            if destination is not None:
                found.append((number, destination))
        for m in HTML_LINK.finditer(prose):
            found.append((number, m.group(1)))
    return found


def pages_of(root):
    pages = []
    readme = os.path.join(root, "README.md")
    if os.path.isfile(readme):
        pages.append(readme)
    for folder, dirs, files in os.walk(os.path.join(root, "docs")):
        dirs.sort()
        pages.extend(os.path.join(folder, f) for f in sorted(files) if f.endswith(".md"))
    return pages


def check(root):
    """Every problem, as 'file:line: link: problem' lines."""
    root = os.path.realpath(root)
    problems = []
    anchor_cache = {}

    def anchors(path):
        if path not in anchor_cache:
            with open(path, encoding="utf-8") as f:
                anchor_cache[path] = anchors_of(f.read())
        return anchor_cache[path]

    readme = os.path.join(root, "README.md")
    if not os.path.isfile(readme):
        problems.append("README.md: missing")
    else:
        size = os.path.getsize(readme)
        if size > README_LIMIT_BYTES:
            problems.append("README.md: %d bytes, over the limit of %d bytes" % (size, README_LIMIT_BYTES))

    for page in pages_of(root):
        name = os.path.relpath(page, root)
        with open(page, encoding="utf-8") as f:
            text = f.read()
        for number, link in links_of(text):
            where = "%s:%d: %s" % (name, number, link)
            if not link:
                problems.append("%s: empty link" % where)
                continue
            if EXTERNAL.match(link):
                continue
            if SCHEME.match(link):
                problems.append("%s: unsupported link scheme" % where)
                continue
            path_part, _, anchor = link.partition("#")
            path_part = urllib.parse.unquote(path_part.split("?", 1)[0])
            if path_part:
                base = root if path_part.startswith("/") else os.path.dirname(page)
                target = os.path.realpath(os.path.join(base, path_part.lstrip("/")))
                if target != root and not target.startswith(root + os.sep):
                    problems.append("%s: points outside the repository" % where)
                    continue
                if not os.path.exists(target):
                    problems.append("%s: no such file %s" % (where, os.path.relpath(target, root)))
                    continue
            else:
                target = page
            if not anchor:
                continue
            if not (os.path.isfile(target) and target.endswith(".md")):
                continue  # GitHub's line anchors (#L10) and the like: not checked
            if urllib.parse.unquote(anchor) not in anchors(target):
                problems.append("%s: no heading or anchor #%s in %s" %
                                (where, anchor, os.path.relpath(target, root)))
    return problems


def self_test():
    """Builds a small tree with known good and bad links; the checker must report exactly the bad ones."""
    pages = {
        "README.md": "\n".join([
            "# Title",                                                  # 1
            "[ok page](docs/a.md) [ok anchor](docs/a.md#the-api-v2)",   # 2
            "[missing page](docs/missing.md)",                          # 3
            "[missing anchor](docs/a.md#no-such-heading)",              # 4
            "![missing image](docs/missing.png)",                       # 5
            "```sh",                                                    # 6
            "[in a fence](nowhere.md)",                                 # 7
            "```",                                                      # 8
            "`[in code](nowhere.md)` [web](https://example.com/x)",     # 9
            "[same page](#title) [dup](docs/a.md#usage-1)",             # 10
            "[explicit](docs/a.md#kept) [outside](../x.md)",            # 11
            "[wrong case](docs/a.md#Usage)",                            # 12
            "[folder](docs) [image ok](docs/pic.png)",                  # 13
            "",
        ]),
        "docs/a.md": "\n".join([
            "# The `API` (v2)",
            "## Usage",
            "## Usage",
            '<a id="kept"></a>',
            "[back](../README.md#title) [bad back](../README.md#nope)",  # 5
            "",
        ]),
        "docs/pic.png": "",
    }
    expected = [
        "README.md:3: docs/missing.md: no such file docs/missing.md",
        "README.md:4: docs/a.md#no-such-heading: no heading or anchor #no-such-heading in docs/a.md",
        "README.md:5: docs/missing.png: no such file docs/missing.png",
        "README.md:11: ../x.md: points outside the repository",
        "README.md:12: docs/a.md#Usage: no heading or anchor #Usage in docs/a.md",
        "docs/a.md:5: ../README.md#nope: no heading or anchor #nope in README.md",
    ]
    failures = []
    with tempfile.TemporaryDirectory() as parent:
        root = os.path.join(parent, "repo")
        for name, text in pages.items():
            path = os.path.join(root, name)
            os.makedirs(os.path.dirname(path), exist_ok=True)
            with open(path, "w", encoding="utf-8") as f:
                f.write(text)
        got = check(root)
        if got != expected:
            failures.append("reported:\n  %s\nexpected:\n  %s" % ("\n  ".join(got), "\n  ".join(expected)))

        # The command line: one line per problem on stdout, exit status 1.
        run = subprocess.run([sys.executable, os.path.abspath(__file__), root],
                             capture_output=True, text=True)
        if run.returncode != 1 or run.stdout.splitlines()[:len(expected)] != expected:
            failures.append("command line: exit %d, output:\n%s%s" % (run.returncode, run.stdout, run.stderr))

        # An oversized README is a problem of its own.
        with open(os.path.join(root, "README.md"), "a", encoding="utf-8") as f:
            f.write("x" * (README_LIMIT_BYTES + 1))
        if not any("over the limit" in p for p in check(root)):
            failures.append("an oversized README.md was not reported")

        # A clean tree passes.
        for name in ("README.md", "docs/a.md"):
            os.remove(os.path.join(root, name))
        with open(os.path.join(root, "README.md"), "w", encoding="utf-8") as f:
            f.write("# Top\n\n[pic](docs/pic.png) [top](#top)\n")
        run = subprocess.run([sys.executable, os.path.abspath(__file__), root],
                             capture_output=True, text=True)
        if run.returncode != 0:
            failures.append("a clean tree failed: exit %d\n%s" % (run.returncode, run.stdout))

    for f in failures:
        print("self-test: " + f)
    print("self-test: %s" % ("FAILED" if failures else "ok"))
    return 1 if failures else 0


def main(argv):
    if argv[1:] == ["--self-test"]:
        return self_test()
    if len(argv) > 2 or (len(argv) == 2 and argv[1].startswith("-")):
        print("usage: check_links.py [ROOT] | --self-test", file=sys.stderr)
        return 2
    root = argv[1] if len(argv) == 2 else os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "..")
    problems = check(root)
    for p in problems:
        print(p)
    if problems:
        print("%d problem(s) in README.md and docs/" % len(problems))
        return 1
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv))
