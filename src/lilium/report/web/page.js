/* page.js: small helpers shared by Lilium's self-contained pages (no network, no server).

   Data arrive in the page itself: JSON in <script type="application/json" id=...> and binary
   arrays as base64 in <script type="application/octet-stream" id=...> (little-endian, as
   lilium.report.workbench writes them). A page opened from file:// cannot write to disk, so
   a file is offered as a data: link download. */
const Page = (function () {
  "use strict";

  /** The parsed JSON of the element `id`. */
  function json(id) { return JSON.parse(document.getElementById(id).textContent); }

  /** The bytes of the base64 text of the element `id`. */
  function bytes(id) {
    const text = atob(document.getElementById(id).textContent.replace(/\s+/g, ""));
    const out = new Uint8Array(text.length);
    for (let i = 0; i < text.length; i++) out[i] = text.charCodeAt(i);
    return out;
  }
  function float32(id) { return new Float32Array(bytes(id).buffer); }
  function uint32(id) { return new Uint32Array(bytes(id).buffer); }

  /** Offer `text` as the download of `link` (an <a download=...>), and click it unless
      `click` is false (a headless test reads the link instead of saving a file). */
  function offerDownload(link, text, mime, click) {
    link.href = "data:" + (mime || "application/json") + ";charset=utf-8," +
      encodeURIComponent(text);
    link.hidden = false;
    if (click !== false) link.click();
  }

  /** The page's query (`?test&yaw=5`). */
  function params() { return new URLSearchParams(location.search); }

  /** A number as text with `digits` decimals, or an en dash when it is not finite. */
  function fixed(x, digits) { return Number.isFinite(x) ? x.toFixed(digits) : "\u2013"; }

  /** A new SVG element with attributes, appended to `parent` (an element of an inline <svg>,
      whose namespace it takes). */
  function svg(tag, attributes, parent) {
    const element = document.createElementNS(parent.namespaceURI, tag);
    for (const [k, v] of Object.entries(attributes || {})) element.setAttribute(k, v);
    parent.append(element);
    return element;
  }

  return {json, bytes, float32, uint32, offerDownload, params, fixed, svg};
})();
