// Loaded (a classic, blocking script) by every test page before anything else runs: every console
// error/warning and uncaught error lands in window.zhcErrors, which the page posts as its report's
// `errors` (tests/js/chromium_page.mjs checks that the list exists; each test that it is empty).
window.zhcErrors = [];
const origError = console.error.bind(console), origWarn = console.warn.bind(console);
console.error = (...a) => { window.zhcErrors.push('console.error: ' + a.join(' ')); origError(...a); };
console.warn = (...a) => { window.zhcErrors.push('console.warn: ' + a.join(' ')); origWarn(...a); };
window.addEventListener('error', (e) => window.zhcErrors.push('error: ' + (e.message || e.type) + ' ' + (e.filename || '') + ':' + (e.lineno || '')));
window.addEventListener('unhandledrejection', (e) => window.zhcErrors.push('unhandled rejection: ' + (e.reason && e.reason.stack || e.reason)));
