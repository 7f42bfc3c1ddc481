// Records script errors and console.error calls into #errors (read by the browser test).
(function () {
  var seen = [];
  function record(text) {
    seen.push(String(text));
    var el = document.getElementById('errors');
    if (el) { el.textContent = seen.join('\n'); }
  }
  window.addEventListener('error', function (e) {
    record('error: ' + e.message + ' (line ' + e.lineno + ')');
  });
  window.addEventListener('unhandledrejection', function (e) {
    record('unhandled rejection: ' + e.reason);
  });
  var original = console.error;
  console.error = function () {
    record('console.error: ' + Array.prototype.join.call(arguments, ' '));
    return original.apply(console, arguments);
  };
  document.addEventListener('DOMContentLoaded', function () {
    if (seen.length) { document.getElementById('errors').textContent = seen.join('\n'); }
  });
})();
