// The claims explorer of report/index.html (netrepro.report.sections.explorer_html): filters the
// table #explore-table by text, paper, verdict and kind. The state lives in the URL's fragment,
// #explore?paper=markov&verdict=differs&kind=claim&q=text, read on load and on every hashchange
// (the scorecard's counts link there). Allowed by the page's content security policy by its
// sha256 hash (netrepro.report.csp.page_policy); without it the whole table is simply shown.
(function () {
  "use strict";
  var root = document.getElementById("explore");
  var table = document.getElementById("explore-table");
  if (!root || !table) { return; }
  var controls = document.getElementById("explore-controls");
  var text = document.getElementById("explore-text");
  var count = document.getElementById("explore-count");
  var reset = document.getElementById("explore-reset");
  var keys = ["paper", "verdict", "kind"];
  var selects = {};
  keys.forEach(function (k) { selects[k] = document.getElementById("explore-" + k); });
  var rows = Array.prototype.slice.call(table.tBodies[0].rows);
  var words = rows.map(function (r) { return r.textContent.toLowerCase(); });

  function apply() {
    var q = text.value.trim().toLowerCase();
    var shown = 0;
    rows.forEach(function (r, i) {
      var ok = (!q || words[i].indexOf(q) >= 0) && keys.every(function (k) {
        return !selects[k].value || r.getAttribute("data-" + k) === selects[k].value;
      });
      r.hidden = !ok;
      if (ok) { shown += 1; }
    });
    count.textContent = shown + " of " + rows.length + " rows shown";
  }

  function query() {
    var parts = [];
    keys.forEach(function (k) {
      if (selects[k].value) { parts.push(k + "=" + encodeURIComponent(selects[k].value)); }
    });
    if (text.value.trim()) { parts.push("q=" + encodeURIComponent(text.value.trim())); }
    return parts.join("&");
  }

  function toHash() {
    var q = query();
    try {
      history.replaceState(null, "", "#explore" + (q ? "?" + q : ""));
    } catch (e) { /* a browser that refuses: the filters still apply */ }
  }

  function fromHash() {
    var hash = location.hash.slice(1);
    if (hash !== "explore" && hash.indexOf("explore?") !== 0) { return false; }
    var params = {};
    hash.slice(8).split("&").forEach(function (pair) {
      var at = pair.indexOf("=");
      if (at > 0) {
        try {
          params[pair.slice(0, at)] = decodeURIComponent(pair.slice(at + 1).replace(/\+/g, " "));
        } catch (e) { /* a malformed value is ignored */ }
      }
    });
    keys.forEach(function (k) {
      var value = params[k] || "";
      selects[k].value = value;
      if (selects[k].value !== value) { selects[k].value = ""; }
    });
    text.value = params.q || "";
    apply();
    root.scrollIntoView();
    return true;
  }

  controls.hidden = false;
  text.addEventListener("input", function () { apply(); toHash(); });
  keys.forEach(function (k) {
    selects[k].addEventListener("change", function () { apply(); toHash(); });
  });
  reset.addEventListener("click", function () {
    text.value = "";
    keys.forEach(function (k) { selects[k].value = ""; });
    apply();
    toHash();
  });
  window.addEventListener("hashchange", fromHash);
  if (!fromHash()) { apply(); }
}());
