// Anchors the generated sources into a library target.
