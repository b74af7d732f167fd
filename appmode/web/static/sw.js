// appmode's service worker: the page's own files, kept for when the server is not
// reachable, and a page that says so. It never keeps the page itself ("/": its
// cookie holds the token), the websocket or anything live.
"use strict";
const CACHE = "appmode-v2";
const OWN = ["/static/app.css", "/static/icon.svg", "/static/offline.html"];

self.addEventListener("install", (event) => {
  event.waitUntil(caches.open(CACHE).then((cache) => cache.addAll(OWN)).then(() => self.skipWaiting()));
});

self.addEventListener("activate", (event) => {
  event.waitUntil(
    caches.keys()
      .then((names) => Promise.all(names.filter((n) => n !== CACHE).map((n) => caches.delete(n))))
      .then(() => self.clients.claim()),
  );
});

self.addEventListener("fetch", (event) => {
  const request = event.request;
  if (request.method !== "GET" || new URL(request.url).origin !== self.location.origin) return;
  if (request.mode === "navigate") {  // the page: always the server's, or the offline one
    event.respondWith(fetch(request).catch(() => caches.match("/static/offline.html")));
    return;
  }
  const path = new URL(request.url).pathname;
  if (OWN.includes(path)) {  // the server's copy first; the kept one when it is gone
    event.respondWith(fetch(request).catch(() => caches.match(path)));
  }
});
