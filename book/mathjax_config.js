// Loaded by every page of the book after Doxygen's own MathJax configuration (MATHJAX_CODEFILE).
// Every displayed equation is numbered, per chapter: (N.k) on the page of chapter N, found from
// the page's file name (chNN_label.html); pages outside the chapters number (k).
MathJax.Hub.Config({
  TeX: {
    equationNumbers: {
      autoNumber: "all",
      formatNumber: function (n) {
        var chapter = /(?:^|\/)ch0*(\d+)_[^\/]*\.html$/.exec(window.location.pathname);
        return chapter ? chapter[1] + "." + n : String(n);
      }
    }
  }
});
