#!/usr/bin/env python3
"""Builds the course's website (tools/site.sh; docs/engineering.md#the-website).

Stages the Markdown of the course into a folder mkdocs builds (every chapter's docs page in order,
the README as the home page, the engineering page, CONTRIBUTING, an exercise map of every chapter
and the gallery), then runs mkdocs with Material (tools/site/mkdocs.yml) and writes the search index
as a script. What it changes on the way:

- the docs checks' comments (<!-- fem:... -->, docs/engineering.md) are taken out;
- links between the docs pages, the README and CONTRIBUTING point at the site's pages; a link to a
  file or folder of the repository, and a code span that names one (`exercises/05_strain_stress/`),
  points at a rendered copy inside the site (source/PATH.html, a folder's listing
  source/PATH/index.html), or at a forge when a base URL is given (--source-url or
  FEM_SITE_SOURCE_URL, e.g. https://github.com/OWNER/fem-course/blob/main/);
- the gallery: a page per scenes/*.toml with the run's web page embedded (RUNS/scenes/NAME/NAME.html,
  written by tools/run_course.sh scenes), its video, its scene file and links to the docs it
  illustrates; a chapter's own scene pages (RUNS/NN_name/**/*.html) get a page each too. A scene
  whose page the run has not written is listed on the gallery's page and printed as missing.

Exit 0 with the site written (missing scene pages are listed, never fatal); 1 with `error: …`.
"""
import argparse
import html
import json
import os
import pathlib
import re
import shutil
import subprocess
import sys
from html.parser import HTMLParser

ROOT = pathlib.Path(__file__).resolve().parents[2]
HERE = pathlib.Path(__file__).resolve().parent
SOURCE_DIRS = ("chapters", "solutions", "exercises", "tests", "programs", "common", "tools", "scenes", "data",
               "cmake", "fuzz", "docs")
RENDERED_LIMIT = 300_000      # a text file larger than this is listed, not rendered
FEM_COMMENT = re.compile(r"<!--\s*/?fem:.*?-->", re.S)
LINK = re.compile(r"(!?\[(?:[^\[\]]|\[[^\]]*\])*\])\(([^)\s]+)\)")
CODE_PATH = re.compile(r"(?<![\[`])`((?:%s)/[^`\s]*)`(?!\]\()" % "|".join(SOURCE_DIRS))


class Site:
    """The staging folder and the map from the repository's files to the site's pages."""

    def __init__(self, staging, extras, source_url):
        self.staging = staging        # the Markdown and figures mkdocs builds from
        self.extras = extras          # the HTML pages copied into the site after mkdocs (mkdocs would
                                      # run a docs folder's .html files through Jinja)
        self.source_url = source_url
        self.tracked = tracked_files()
        self.sources = set()          # repository paths (files and folders) the pages link to
        # repository Markdown page -> its page in the site (relative to the staging folder)
        self.pages = {"README.md": "index.md", "CONTRIBUTING.md": "contributing.md"}
        for doc in sorted((ROOT / "docs").glob("*.md")):
            self.pages[f"docs/{doc.name}"] = doc.name

    def is_dir(self, path):
        return path == "" or any(f.startswith(path.rstrip("/") + "/") for f in self.tracked)

    def exists(self, path):
        return path.rstrip("/") in self.tracked or self.is_dir(path.rstrip("/"))

    def link(self, target, page_repo_path, page_site_path):
        """The site's link for a link `target` written in the repository file page_repo_path, from the
        site page page_site_path; None when the target is not in the repository (left as written)."""
        if re.match(r"^[a-z]+:|^//|^#", target):
            return None
        path, _, fragment = target.partition("#")
        resolved = os.path.normpath(os.path.join(os.path.dirname(page_repo_path), path)).replace(os.sep, "/")
        if resolved.startswith("..") or not self.exists(resolved):
            return None
        fragment = "#" + fragment if fragment else ""
        if resolved in self.pages:
            site_path = self.pages[resolved]
        elif resolved.startswith("docs/figures/"):
            site_path = resolved[len("docs/"):]
        else:
            return self.source_link(resolved, page_site_path) + fragment
        return os.path.relpath(site_path, os.path.dirname(page_site_path) or ".") + fragment

    def source_link(self, repo_path, page_site_path):
        """A link to a file or folder of the repository: the forge's, or the rendered copy's."""
        repo_path = repo_path.rstrip("/")
        if self.source_url:
            return self.source_url.rstrip("/") + "/" + repo_path
        self.sources.add(repo_path)
        target = f"source/{repo_path}/index.html" if self.is_dir(repo_path) else f"source/{repo_path}.html"
        return os.path.relpath(target, os.path.dirname(page_site_path) or ".")

    def markdown(self, text, page_repo_path, page_site_path):
        """The Markdown of a page for the site: fem comments out, links and path code spans rewritten."""
        text = FEM_COMMENT.sub("", text)
        # [a, b](x, y) is mathematics, not a link (CommonMark's destinations hold no space; Python-Markdown's may)
        text = re.sub(r"\]\(([^)\n]*\s[^)\n]*)\)", lambda m: "]\\(" + m.group(1) + ")", text)
        out, fenced = [], False
        for line in text.split("\n"):
            if line.lstrip().startswith(("```", "~~~")):
                fenced = not fenced
            if not fenced and not line.startswith("    "):
                line = LINK.sub(lambda m: m.group(1) + "(" + (self.link(m.group(2), page_repo_path, page_site_path)
                                                              or m.group(2)) + ")", line)
                line = CODE_PATH.sub(lambda m: self.code_link(m, page_site_path), line)
            out.append(line)
        return "\n".join(out)

    def code_link(self, match, page_site_path):
        path = match.group(1)
        bare = re.sub(r"[:#].*$", "", path).rstrip(".,;")
        if not self.exists(bare):
            return match.group(0)
        if bare.startswith("docs/") and bare in self.pages:
            return f"[{match.group(0)}]({os.path.relpath(self.pages[bare], os.path.dirname(page_site_path) or '.')})"
        return f"[{match.group(0)}]({self.source_link(bare, page_site_path)})"

    def write(self, site_path, text):
        target = self.staging / site_path
        target.parent.mkdir(parents=True, exist_ok=True)
        target.write_text(text, encoding="utf-8")


def tracked_files():
    """The repository's files (git's list; every file under the source folders without git)."""
    try:
        listed = subprocess.run(["git", "ls-files"], cwd=ROOT, capture_output=True, text=True, check=True).stdout
        return set(line for line in listed.splitlines() if line)
    except (OSError, subprocess.CalledProcessError):
        found = set()
        for folder in SOURCE_DIRS:
            found.update(str(p.relative_to(ROOT)) for p in (ROOT / folder).rglob("*") if p.is_file())
        return found | {"README.md", "CONTRIBUTING.md", "LICENSE", "CMakeLists.txt", "CMakePresets.json"}


def title_of(markdown_text, fallback):
    found = re.search(r"^# (.+)$", markdown_text, re.M)
    return found.group(1).strip() if found else fallback


SOURCE_PAGE = """<!DOCTYPE html>
<html lang="en"><head><meta charset="utf-8"><meta name="viewport" content="width=device-width, initial-scale=1">
<title>{title} · fem-course</title><link rel="stylesheet" href="{css}"></head>
<body class="fem-source"><nav><a href="{home}">fem-course</a> / {crumbs}</nav>
{body}
</body></html>
"""


def render_sources(site, site_dir):
    """Writes the rendered copies of every linked file and folder into site_dir/source/ (the staging
    folder, which mkdocs copies into the site as it is): a text file
    as an HTML page of its lines, a folder as a listing (its files rendered too), an image copied."""
    pending, done = sorted(site.sources), set()
    while pending:
        path = pending.pop()
        if path in done:
            continue
        done.add(path)
        is_dir = site.is_dir(path)
        page = f"source/{path}/index.html" if is_dir else f"source/{path}.html"
        up = os.path.relpath(".", os.path.dirname(page))
        parts = path.split("/") if path else []
        crumbs = []
        for i, part in enumerate(parts):
            last = i == len(parts) - 1
            listing = os.path.relpath("source/" + "/".join(parts[:i + 1]) + "/index.html", os.path.dirname(page))
            crumbs.append(html.escape(part) if last else f'<a href="{listing}">{html.escape(part)}</a>')
        if is_dir:
            prefix = path + "/" if path else ""
            children = sorted({f[len(prefix):].split("/")[0] + ("/" if "/" in f[len(prefix):] else "")
                               for f in site.tracked if f.startswith(prefix)})
            rows = []
            for child in children:
                child_path = prefix + child.rstrip("/")
                if child.endswith("/"):
                    href = f"{child.rstrip('/')}/index.html"
                    pending.append(child_path)
                elif child_path in site.pages or child_path.startswith("docs/figures/"):
                    own = site.pages.get(child_path, child_path[len("docs/"):]).replace(".md", ".html")
                    href = os.path.relpath(own, os.path.dirname(page))
                else:
                    href = source_file_href(site, child_path, pending)
                rows.append(f'<li><a href="{href}">{html.escape(child)}</a></li>' if href else
                            f"<li>{html.escape(child)} <span class=\"note\">(not copied: {file_size(child_path)})</span></li>")
            body = f"<h1>{html.escape(path or 'fem-course')}/</h1><ul>{''.join(rows)}</ul>"
        else:
            source = ROOT / path
            if source.suffix.lower() in (".png", ".jpg", ".svg", ".gif"):
                (site_dir / "source" / path).parent.mkdir(parents=True, exist_ok=True)
                shutil.copyfile(source, site_dir / "source" / path)
                body = f'<h1>{html.escape(path)}</h1><img src="{html.escape(source.name)}" alt="{html.escape(path)}">'
            else:
                text = source.read_bytes()[:RENDERED_LIMIT].decode("utf-8", errors="replace")
                more = source.stat().st_size > RENDERED_LIMIT
                lines = "".join(f'<span id="L{n}" class="line">{html.escape(line)}\n</span>'
                                for n, line in enumerate(text.split("\n"), 1))
                body = (f"<h1>{html.escape(path)}</h1><pre>{lines}</pre>" +
                        (f'<p class="note">… the first {RENDERED_LIMIT:,} bytes of {file_size(path)}</p>' if more else ""))
        target = site_dir / page
        target.parent.mkdir(parents=True, exist_ok=True)
        target.write_text(SOURCE_PAGE.format(title=html.escape(path or "fem-course"), css=f"{up}/assets/fem_site.css",
                                             home=f"{up}/index.html", crumbs=" / ".join(crumbs), body=body),
                          encoding="utf-8")


def source_file_href(site, path, pending):
    """A folder listing's link to one of its files (queued for rendering), or None for a binary file."""
    if is_text(ROOT / path) or (ROOT / path).suffix.lower() in (".png", ".jpg", ".svg", ".gif"):
        pending.append(path)
        return os.path.basename(path) + ".html"
    return None


def is_text(path):
    try:
        head = path.read_bytes()[:4096]
    except OSError:
        return False
    if b"\0" in head:
        return False
    try:
        head.decode("utf-8")
        return True
    except UnicodeDecodeError as error:
        return error.start > 4090      # a character cut at the 4096th byte


def file_size(path):
    return f"{(ROOT / path).stat().st_size / 1e6:.1f} MB"


def gallery_table():
    """{scene name: what it shows} from docs/scenes.md's gallery table."""
    text = (ROOT / "docs/scenes.md").read_text(encoding="utf-8")
    rows = {}
    for m in re.finditer(r"^\| `scenes/(\w+)\.toml` \| (.+?) \| (.+?) \|$", text, re.M):
        rows[m.group(1)] = (m.group(2), m.group(3))
    return rows


def illustrates(scene_text):
    """The docs (page, section, why) a scene illustrates, from what its file uses."""
    found = [("scenes.md#the-gallery", "the gallery"), ("scenes.md#the-web-page", "the web page")]
    if re.search(r"^(bodies|self_contact) = true", scene_text, re.M):
        found += [("scenes.md#bodies-against-bodies", "bodies against bodies"),
                  ("15_body_contact.md", "chapter 15: bodies against bodies")]
    if re.search(r"^\[\[obstacle\]\]", scene_text, re.M):
        found += [("scenes.md#obstacles", "obstacles"), ("14_contact.md", "chapter 14: contact with obstacles")]
    if re.search(r"^\[(\[)?(body\.)?skin\]", scene_text, re.M):
        found += [("scenes.md#skin", "skin"), ("13_skinning.md", "chapter 13: skinning")]
    if "model = \"auto\"" in scene_text:
        found.append(("scenes.md#model-auto", "model auto"))
    for number in sorted(set(re.findall(r"chapter (1[0-6]|0[1-9])", scene_text))):
        doc = next((ROOT / "docs").glob(f"{number}_*.md"), None)
        if doc and not any(page.startswith(doc.name) for page, _ in found):
            found.append((doc.name, f"chapter {number}: {title_of(doc.read_text(encoding='utf-8'), doc.stem)}"))
    return found


def stage_gallery(site, runs):
    """The gallery's pages; returns (nav entries, names of scenes whose web page is missing)."""
    table = gallery_table()
    scenes = sorted((ROOT / "scenes").glob("*.toml"))
    missing, nav = [], []
    rows = []
    for scene in scenes:
        name = scene.stem
        text = scene.read_text(encoding="utf-8")
        what, model = table.get(name, (title_of_scene(text, name), ""))
        what = what.replace("](#", "](../scenes.md#")   # the table's links within docs/scenes.md
        run = runs / "scenes" / name
        page = run / f"{name}.html"
        videos = sorted(run.glob("*.mp4")) if run.is_dir() else []
        site_page = f"gallery/{name}.md"
        lines = [f"# {name}", "", site.markdown(what, "docs/scenes.md", site_page), ""]
        if page.is_file():
            (site.extras / "gallery" / "scenes").mkdir(parents=True, exist_ok=True)
            shutil.copyfile(page, site.extras / "gallery" / "scenes" / f"{name}.html")
            lines += [f'<div class="fem-player"><iframe src="scenes/{name}.html" title="{html.escape(name)}: the run, '
                      'playing" loading="lazy" allow="fullscreen"></iframe></div>', "",
                      f"The run's web page, playing: drag to orbit, the wheel zooms, space pauses "
                      f"([open it alone](scenes/{name}.html), or [at its first frame](scenes/{name}.html#frame=0)).", ""]
        else:
            missing.append(name)
            lines += ['!!! warning "Not built yet"',
                      f"    This scene's web page is not in `{runs_label(runs)}/scenes/{name}/`: "
                      "`tools/run_course.sh scenes`, then `tools/site.sh`, put it here.", ""]
        for video in videos:
            (site.staging / "gallery" / "scenes").mkdir(parents=True, exist_ok=True)
            shutil.copyfile(video, site.staging / "gallery" / "scenes" / video.name)
            lines += ["## The video", "", f'<video controls preload="metadata" src="scenes/{video.name}"></video>', ""]
        lines += ["## What it illustrates", ""]
        lines += [f"- [{why}](../{target})" for target, why in illustrates(text)]
        lines += ["", f"## The scene file `scenes/{name}.toml`", "",
                  f"Model in the file: {model}. Run it: `build/release/bin/fem_scene scenes/{name}.toml --html`"
                  if model else f"Run it: `build/release/bin/fem_scene scenes/{name}.toml --html`", "",
                  "```toml", text.rstrip("\n"), "```", ""]
        site.write(site_page, "\n".join(lines))
        nav.append((name, site_page))
        picture = f"figures/scenes/{name}.png"
        thumb = f"[![{name}](../{picture}){{ width=240 }}]({name}.md)" if (site.staging / picture).exists() else ""
        rows.append(f"| {thumb} | [{name}]({name}.md) | {site.markdown(what, 'docs/scenes.md', 'gallery/index.md')}"
                    f"{' **(web page not built)**' if name in missing else ''} |")
    chapter_pages = []
    for page in sorted(runs.glob("[0-9][0-9]_*/**/*.html")):
        chapter = page.relative_to(runs).parts[0]
        target = f"gallery/{chapter}/{page.name}"
        (site.extras / target).parent.mkdir(parents=True, exist_ok=True)
        shutil.copyfile(page, site.extras / target)
        site_page = f"gallery/{chapter}_{page.stem}.md"
        doc = f"{chapter}.md" if (ROOT / "docs" / f"{chapter}.md").exists() else "index.md"
        site.write(site_page, "\n".join([
            f"# {chapter}: {page.stem}", "",
            f'<div class="fem-player"><iframe src="{chapter}/{page.name}" title="{html.escape(page.stem)}" '
            'loading="lazy"></iframe></div>', "",
            f"Written by the chapter's executable into `{runs_label(runs)}/{page.relative_to(runs)}`; "
            f"its text: [{chapter}](../{doc}).", ""]))
        chapter_pages.append((f"{chapter}: {page.stem}", site_page))
    index = ["# The gallery", "",
             "Every scene of `scenes/` as its run's web page, playing in place (drag to orbit), with its video, "
             "its scene file and the docs it illustrates. How the scenes are made: [scenes](../scenes.md); "
             "each page is written by `fem_scene SCENE.toml --html` ([the web page](../scenes.md#the-web-page)).", ""]
    if missing:
        index += ['!!! warning "Scene pages not built yet"',
                  f"    {len(missing)} of {len(scenes)} scenes have no web page in `{runs_label(runs)}/scenes/`: "
                  + ", ".join(missing) + ". Run `tools/run_course.sh scenes`, then `tools/site.sh`.", ""]
    index += ["| | scene | what it shows |", "|---|---|---|"] + rows + [""]
    if chapter_pages:
        index += ["## The chapters' own scene pages", ""] + [f"- [{t}]({p[len('gallery/'):]})" for t, p in chapter_pages] + [""]
    site.write("gallery/index.md", "\n".join(index))
    return [("The gallery", "gallery/index.md")] + nav + chapter_pages, missing


def title_of_scene(text, fallback):
    found = re.search(r'^title = "(.*)"', text, re.M)
    return found.group(1) if found else fallback


def runs_label(runs):
    try:
        return str(runs.resolve().relative_to(ROOT))
    except ValueError:
        return str(runs)


def stage_exercises(site, chapters):
    """One page with every chapter's Exercises section (exercise → stub file → tests → builds on)."""
    lines = ["# Exercises", "",
             "Every chapter's exercise map, as its docs page has it: the exercise, the stub file to fill in, "
             "the tests that grade it and what it builds on. The student's loop is on the [home page](index.md).", ""]
    for doc in chapters:
        text = (ROOT / "docs" / doc).read_text(encoding="utf-8")
        section = re.search(r"^## Exercises\n(.*?)(?=^## |\Z)", text, re.M | re.S)
        if not section:
            continue
        table = re.search(r"^\|.*?(?=\n\n|\Z)", section.group(1), re.M | re.S)
        if not table:
            continue
        body = re.sub(r"\]\(#", f"]({doc}#", table.group(0))
        lines += [f"## [{title_of(text, doc)}]({doc}#exercises)", "", site.markdown(body, f"docs/{doc}", "exercises.md"), ""]
    site.write("exercises.md", "\n".join(lines))


class Sections(HTMLParser):
    """The text of a page's article, split at its headings: [(heading, id, text)]."""

    def __init__(self):
        super().__init__(convert_charrefs=True)
        self.depth = 0            # > 0 inside the article
        self.skip = 0             # inside a headerlink, script or style
        self.heading = None       # (level, id) while inside a heading
        self.sections = [["", "", []]]

    def handle_starttag(self, tag, attrs):
        attrs = dict(attrs)
        if tag == "article":
            self.depth += 1
        if self.depth == 0:
            return
        if tag in ("script", "style") or (tag == "a" and "headerlink" in (attrs.get("class") or "")):
            self.skip += 1
        elif re.fullmatch(r"h[1-4]", tag):
            self.heading = tag
            self.sections.append(["", attrs.get("id", ""), []])

    def handle_endtag(self, tag):
        if tag == "article":
            self.depth -= 1
        if self.depth == 0:
            return
        if tag in ("script", "style") or (tag == "a" and self.skip):
            self.skip = max(0, self.skip - 1)
        elif tag == self.heading:
            self.heading = None

    def handle_data(self, data):
        if self.depth == 0 or self.skip:
            return
        if self.heading:
            self.sections[-1][0] += data
        else:
            self.sections[-1][2].append(data)


def write_search_index(site_dir, pages):
    """site_dir/assets/fem_search_index.js: window.FEM_SEARCH_INDEX = [{page, title, section, url, text}]
    of every page's sections, loaded by a <script> tag (a fetch() of JSON is blocked on file://)."""
    entries = []
    for page_title, html_path in pages:
        parser = Sections()
        parser.feed((site_dir / html_path).read_text(encoding="utf-8"))
        for heading, anchor, text in parser.sections:
            words = re.sub(r"\s+", " ", " ".join(text)).strip()
            if not heading and not words:
                continue
            entries.append({"page": page_title, "section": heading.strip() or page_title,
                            "url": html_path + (f"#{anchor}" if anchor else ""), "text": words})
    script = "window.FEM_SEARCH_INDEX = " + json.dumps(entries, ensure_ascii=False, separators=(",", ":")) + ";\n"
    (site_dir / "assets").mkdir(exist_ok=True)
    (site_dir / "assets" / "fem_search_index.js").write_text(script, encoding="utf-8")
    return len(entries)


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--runs", default="out", help="the run command's output folder (tools/run_course.sh): out/")
    parser.add_argument("--site", default="site", help="the folder the website is written to: site/")
    parser.add_argument("--staging", default="build/site_staging", help="the Markdown mkdocs builds from")
    parser.add_argument("--source-url", default=os.environ.get("FEM_SITE_SOURCE_URL", ""),
                        help="links to source files go to URL/PATH (a forge's, e.g. https://github.com/OWNER/"
                             "fem-course/blob/main) instead of rendered copies in the site (also FEM_SITE_SOURCE_URL)")
    args = parser.parse_args()
    runs = (ROOT / args.runs).resolve() if not os.path.isabs(args.runs) else pathlib.Path(args.runs)
    site_dir = (ROOT / args.site).resolve() if not os.path.isabs(args.site) else pathlib.Path(args.site)
    staging = (ROOT / args.staging).resolve() if not os.path.isabs(args.staging) else pathlib.Path(args.staging)
    if args.source_url and not re.match(r"^https?://", args.source_url):
        print(f"error: --source-url {args.source_url!r}: a base URL starting with http:// or https:// expected")
        return 1
    if site_dir in (ROOT, ROOT / "docs") or ROOT.is_relative_to(site_dir):
        print(f"error: --site {site_dir}: would delete the repository; give a folder of its own (site/)")
        return 1
    if shutil.which("mkdocs") is None:
        print("error: no mkdocs: tools/setup.sh installs Debian's mkdocs and mkdocs-material")
        return 1

    shutil.rmtree(staging, ignore_errors=True)
    (staging / "docs").mkdir(parents=True)
    (staging / "extras").mkdir()
    site = Site(staging / "docs", staging / "extras", args.source_url)
    shutil.copytree(ROOT / "docs" / "figures", site.staging / "figures")
    shutil.copytree(HERE / "assets", site.staging / "assets")

    chapters = sorted(p.name for p in (ROOT / "docs").glob("[0-9][0-9]_*.md"))
    titles = {}
    for repo_path, site_path in site.pages.items():
        text = (ROOT / repo_path).read_text(encoding="utf-8")
        titles[site_path] = title_of(text, site_path)
        site.write(site_path, site.markdown(text, repo_path, site_path))
    stage_exercises(site, chapters)
    gallery_nav, missing = stage_gallery(site, runs)

    def nav_line(title, path, indent):
        return f"{' ' * indent}- {json.dumps(title, ensure_ascii=False)}: {json.dumps(path)}"
    nav = ["nav:", nav_line("Home", "index.md", 2), "  - Chapters:"]
    nav += [nav_line(f"{doc[:2]} {titles[doc].split(':')[-1].strip()}" if ":" in titles[doc] else titles[doc], doc, 6)
            for doc in chapters]
    nav += [nav_line("Scenes", "scenes.md", 6), "  - Gallery:"]
    nav += [nav_line(title, path, 6) for title, path in gallery_nav]
    nav += [nav_line("Exercises", "exercises.md", 2), nav_line("Engineering", "engineering.md", 2),
            nav_line("Contributing", "contributing.md", 2)]
    config = (HERE / "mkdocs.yml").read_text(encoding="utf-8") + "\n".join(
        [f"docs_dir: {json.dumps(str(site.staging))}", f"site_dir: {json.dumps(str(site_dir))}"] + nav) + "\n"
    (staging / "mkdocs.yml").write_text(config, encoding="utf-8")
    render_sources(site, site.extras)
    build = subprocess.run(["mkdocs", "build", "--clean", "-f", str(staging / "mkdocs.yml")], capture_output=True, text=True)
    if build.returncode != 0:
        print(f"error: mkdocs build failed:\n{build.stdout}{build.stderr}")
        return 1
    for line in (build.stdout + build.stderr).splitlines():
        added = re.search(r"contains a link to '([^']+)' which is not found", line)
        if line.startswith("WARNING") and not (added and (site.extras / added.group(1)).exists()):
            print("mkdocs: " + line)
    shutil.copytree(site.extras, site_dir, dirs_exist_ok=True)
    (site_dir / "404.html").unlink(missing_ok=True)     # its links are from the server's root: none on file://
    pages = [(titles.get(p, p), p.replace(".md", ".html")) for p in site.pages.values()]
    pages += [("Exercises", "exercises.html")] + [(t, p.replace(".md", ".html")) for t, p in gallery_nav]
    entries = write_search_index(site_dir, pages)
    print(f"site: {site_dir}/index.html ({len(pages)} pages, {len(site.sources)} source files and folders linked, "
          f"{entries} search entries)")
    if missing:
        print(f"scene pages missing ({len(missing)} of {len(list((ROOT / 'scenes').glob('*.toml')))}; "
              f"tools/run_course.sh scenes writes them into {runs_label(runs)}/scenes/): {', '.join(missing)}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
