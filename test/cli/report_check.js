// test/cli/report_check.js: checks of a towstab report page in a real
// browser, appended to a copy of the page by test/cli/report_browser.sh.
// When the page has loaded (every image with it), it opens every
// <details> (so that folded tables are laid out too) and writes its
// results into a pre element with the id towstab-checks: "PASS ..." or "FAIL ..."
// line per check, "IMAGES n" (the number of images) and "DONE" last;
// chromium --dump-dom prints them.
(function () {
  "use strict";
  var lines = [];
  function check(ok, what) {
    lines.push((ok ? "PASS " : "FAIL ") + what);
  }
  function describe(el) {
    var t = (el.textContent || "").replace(/\s+/g, " ").trim();
    return el.tagName.toLowerCase() + " '" + t.slice(0, 60) + "'";
  }
  function overflows(el) {
    // A box that is laid out (not inline, not hidden) whose content is
    // wider than it: text that runs out of its box.
    return el.clientWidth > 0 && el.scrollWidth > el.clientWidth + 1;
  }
  function run() {
    var i, imgs = document.images, bad = [];
    lines.push("IMAGES " + imgs.length);
    for (i = 0; i < imgs.length; i++) {
      var im = imgs[i];
      if (!(im.complete && im.naturalWidth > 0 && im.naturalHeight > 0))
        bad.push(im.alt || ("image " + (i + 1)));
      else if (!/^data:image\/svg\+xml,/.test(im.getAttribute("src")))
        bad.push((im.alt || ("image " + (i + 1))) + " (not an SVG data URI)");
    }
    check(bad.length === 0, "every image loads (naturalWidth > 0) from an " +
          "SVG data URI" + (bad.length ? ": not " + bad.join("; ") : ""));

    var texts = document.querySelectorAll(
        "td, th, p, li, pre, h1, h2, h3, h4, h5, h6, summary, figcaption, " +
        "figure, .verdict, section");
    var over = [];
    for (i = 0; i < texts.length; i++)
      if (overflows(texts[i])) over.push(describe(texts[i]) + " " +
        texts[i].scrollWidth + " > " + texts[i].clientWidth + " px");
    check(over.length === 0, texts.length + " text boxes (cells, " +
          "paragraphs, headings, captions), none overflows" +
          (over.length ? ": " + over.slice(0, 5).join("; ") : ""));

    var wide = document.querySelectorAll(".wide"), scroll = [];
    for (i = 0; i < wide.length; i++)
      if (overflows(wide[i])) scroll.push(describe(wide[i].querySelector(
        "tr") || wide[i]) + " " + wide[i].scrollWidth + " > " +
        wide[i].clientWidth + " px");
    check(scroll.length === 0, wide.length + " tables fit the page " +
          "without scrolling" + (scroll.length ? ": " +
          scroll.slice(0, 5).join("; ") : ""));

    var doc = document.documentElement;
    check(doc.scrollWidth <= window.innerWidth, "the page is no wider than " +
          "the window (" + doc.scrollWidth + " <= " + window.innerWidth +
          " px)");

    var res = performance.getEntriesByType("resource"), net = [];
    for (i = 0; i < res.length; i++)
      if (!/^data:/.test(res[i].name)) net.push(res[i].name);
    check(net.length === 0, "nothing fetched but data URIs (" + res.length +
          " resources)" + (net.length ? ": " + net.join(", ") : ""));

    var out = document.createElement("pre");
    out.id = "towstab-checks";
    out.textContent = lines.join("\n") + "\nDONE\n";
    document.body.appendChild(out);
  }
  // The load event comes after every image has loaded or failed; the
  // checks run inside it, synchronously (reading sizes lays the page out),
  // so that the DOM chromium dumps after the event holds their results.
  window.addEventListener("load", function () {
    var ds = document.querySelectorAll("details"), i;
    for (i = 0; i < ds.length; i++) ds[i].open = true;
    run();
  });
})();
