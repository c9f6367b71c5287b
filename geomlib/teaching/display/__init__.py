"""Display: the 3D view and its still pictures, colours and glyphs, the controls that drive views, the website's widget states, front-ends."""
