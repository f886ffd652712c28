"""``softdesign report``: an HTML page of plots of a build folder (the morph, surfaces, fit, kinematics).

:mod:`.build_folder` reloads a build, the ``*_figures`` modules draw one topic
each with matplotlib's Agg canvas, :mod:`.tables` extracts the manifest's
figures and checks, :mod:`.html_page` writes the page and :mod:`.writer`
puts it all into ``BUILD_DIR/report/`` atomically.
"""
