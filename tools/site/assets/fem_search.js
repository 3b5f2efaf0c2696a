// The course website's search (tools/site.sh; docs/engineering.md#the-website): works from file:// and
// from any web server with no network. The index (fem_search_index.js, written by tools/site/build_site.py:
// every page's sections, their text) is loaded by a <script> tag on the first use of the box, since
// browsers block fetch() and web workers of file:// pages. A query's words must all be in a section
// (its heading or its text, case-insensitive); sections rank by how often they hold them, a word in the
// heading counting 10 times. Enter opens the first result, ↑ ↓ choose, Escape closes.
"use strict";
(function () {
  const me = document.currentScript;
  const base = me ? me.src.replace(/assets\/fem_search\.js(\?.*)?$/, "") : "";
  let index = null, loading = null;

  function load() {
    if (index) return Promise.resolve(index);
    if (loading) return loading;
    loading = new Promise(function (resolve, reject) {
      const script = document.createElement("script");
      script.src = base + "assets/fem_search_index.js";
      script.onload = function () { index = window.FEM_SEARCH_INDEX || []; resolve(index); };
      script.onerror = function () { reject(new Error("the search index " + script.src + " did not load")); };
      document.head.appendChild(script);
    });
    return loading;
  }

  function count(haystack, word) {
    let n = 0;
    for (let at = haystack.indexOf(word); at >= 0; at = haystack.indexOf(word, at + word.length)) ++n;
    return n;
  }

  // The sections holding every word of the query, best first: [{entry, score}]
  function search(query) {
    const words = query.toLowerCase().split(/\s+/).filter(function (w) { return w.length > 0; });
    if (words.length === 0) return [];
    const found = [];
    for (const entry of index) {
      const heading = entry.section.toLowerCase(), text = entry.text.toLowerCase();
      let score = 0, all = true;
      for (const w of words) {
        const n = 10 * count(heading, w) + count(text, w);
        if (n === 0) { all = false; break; }
        score += n;
      }
      if (all) found.push({ entry: entry, score: score });
    }
    found.sort(function (a, b) { return b.score - a.score; });
    return found.slice(0, 40);
  }

  function escape(s) {
    return s.replace(/[&<>"]/g, function (c) { return { "&": "&amp;", "<": "&lt;", ">": "&gt;", '"': "&quot;" }[c]; });
  }
  function highlight(text, words) {
    let out = escape(text);
    for (const w of words) {
      const pattern = new RegExp("(" + escape(w).replace(/[.*+?^${}()|[\]\\]/g, "\\$&") + ")", "gi");
      out = out.replace(pattern, "<mark>$1</mark>");
    }
    return out;
  }
  function snippet(text, words) {
    const lower = text.toLowerCase();
    let at = -1;
    for (const w of words) { const i = lower.indexOf(w); if (i >= 0 && (at < 0 || i < at)) at = i; }
    const start = Math.max(0, at - 60);
    return (start > 0 ? "… " : "") + text.slice(start, start + 180) + (start + 180 < text.length ? " …" : "");
  }

  function install() {
    const header = document.querySelector(".md-header__inner");
    if (!header) return;
    const box = document.createElement("div");
    box.className = "fem-search";
    box.innerHTML = '<input type="search" id="fem-search-input" placeholder="Search the course" aria-label="Search the course" ' +
                    'autocomplete="off"><div class="fem-results" id="fem-search-results" hidden></div>';
    const before = header.querySelector(".md-header__source");
    header.insertBefore(box, before);
    const input = box.querySelector("input"), results = box.querySelector(".fem-results");
    let active = 0;

    function show() {
      const query = input.value.trim();
      if (!query) { results.hidden = true; return; }
      load().then(function () {
        const words = query.toLowerCase().split(/\s+/).filter(function (w) { return w.length > 0; });
        const found = search(query);
        active = 0;
        results.innerHTML = found.length === 0 ? '<div class="fem-none">No section holds all of: ' + escape(query) + "</div>" :
          found.map(function (f, k) {
            const e = f.entry, where = e.section === e.page ? e.page : e.page + " › " + e.section;
            return '<a href="' + base + e.url + '"' + (k === 0 ? ' class="fem-active"' : "") + '><div class="fem-where">' +
                   escape(where) + '</div><div class="fem-snippet">' + highlight(snippet(e.text, words), words) + "</div></a>";
          }).join("");
        results.hidden = false;
      }, function (error) {
        results.innerHTML = '<div class="fem-none">' + escape(error.message) + "</div>";
        results.hidden = false;
      });
    }
    function choose(k) {
      const links = results.querySelectorAll("a");
      if (links.length === 0) return;
      active = (k + links.length) % links.length;
      links.forEach(function (a, i) { a.classList.toggle("fem-active", i === active); });
      links[active].scrollIntoView({ block: "nearest" });
    }
    input.addEventListener("focus", function () { load().catch(function () {}); if (input.value) show(); });
    input.addEventListener("input", show);
    input.addEventListener("keydown", function (event) {
      const links = results.querySelectorAll("a");
      if (event.key === "Enter" && links.length > 0) { location.href = links[active].href; event.preventDefault(); }
      else if (event.key === "ArrowDown") { choose(active + 1); event.preventDefault(); }
      else if (event.key === "ArrowUp") { choose(active - 1); event.preventDefault(); }
      else if (event.key === "Escape") { results.hidden = true; input.blur(); }
    });
    document.addEventListener("click", function (event) { if (!box.contains(event.target)) results.hidden = true; });
    // "/" or "s" focuses the box, as Material's own search does
    document.addEventListener("keydown", function (event) {
      if ((event.key === "/" || event.key === "s") && document.activeElement.tagName !== "INPUT") {
        input.focus(); event.preventDefault();
      }
    });
  }
  if (document.readyState === "loading") document.addEventListener("DOMContentLoaded", install);
  else install();
})();
