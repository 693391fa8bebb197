"""'replica figures OUT_DIR': the paper's Figs. 2-7 from the shipped data (Darling & Ferwerda,
"Seeing Virtual Objects: Simulating Reflective Surfaces on Emissive Displays").

Run by 'replica figures' (platform/cli/figures_command.cpp) with /usr/bin/python3:
    figures.py OUT_DIR --replica BIN --data DATA_DIR [--scale S] [--only 6,7] [--gl]
Each figure N writes OUT_DIR/figN.png, figN.txt (caption, and the command line of each panel) and
figN.csv (the numbers behind it); the rendered panels (absolute XYZ OpenEXR) stay in
OUT_DIR/panels/. Progress goes to stderr."""
import argparse
import json
import os
import sys

sys.dont_write_bytecode = True  # no __pycache__ in the data folder (installed read-only)
sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))

import matplotlib  # noqa: E402

matplotlib.use('Agg')
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402

import figlib as fl  # noqa: E402
import figshape  # noqa: E402
import figures_more  # noqa: E402

LAMPS = {'tungsten': 'A', 'd50-fluorescent': 'F8', 'd65-fluorescent': 'F7'}
TITLES = {'tungsten': 'tungsten (CIE A)', 'd50-fluorescent': 'D50 simulator (CIE F8)',
          'd65-fluorescent': 'D65 simulator (CIE F7)'}
WB_CCT = 5500.0  # the paper's fixed camera white balance (Fig. 6)


def short(path):
    """A path under the working folder as a relative one: the captions' commands read as typed."""
    rel = os.path.relpath(path)
    return path if rel.startswith('..') else rel


class Context:
    def __init__(self, args):
        self.out, self.data, self.scale = args.out_dir, args.data, args.scale
        self.panels = os.path.join(self.out, 'panels')
        os.makedirs(self.panels, exist_ok=True)
        self.colour = fl.Colour(self.data)
        self.run = fl.Runner(args.replica, ['--gl'] if args.gl else [])

    def scene(self, name):
        return short(os.path.join(self.data, 'scenes', name))

    def size(self, w, h):
        """A panel's size: the scene's texels times the scale (the --size option's)."""
        return f'{max(8, round(w * self.scale))}x{max(8, round(h * self.scale))}'

    def panel(self, name):
        return short(os.path.join(self.panels, name))

    def path(self, name):
        return os.path.join(self.out, name)

    def save(self, fig, n):
        fig.savefig(self.path(f'fig{n}.png'), dpi=80)
        plt.close(fig)


def scene_palette(ctx, name):
    s = json.load(open(os.path.join(ctx.scene(name), 'scene.json')))
    return [p['name'] for p in s['palette']], [np.array(p['reflectance']) for p in s['palette']]


def patch_means(ctx, scene, frame, erode=3):
    """Mean XYZ of each palette entry's pixels in a frame that covers the scene, away from edges
    (texels whose neighbours within 'erode' texels share the entry)."""
    idx = fl.read_exr(os.path.join(ctx.scene(scene), 'material.exr'))['A'].astype(int)
    keep = np.ones_like(idx, bool)
    for dy in range(-erode, erode + 1):
        for dx in range(-erode, erode + 1):
            keep &= np.roll(np.roll(idx, dy, 0), dx, 1) == idx
    h, w = frame.shape[:2]
    ty = ((np.arange(h) + 0.5) * idx.shape[0] / h).astype(int)
    tx = ((np.arange(w) + 0.5) * idx.shape[1] / w).astype(int)
    pix, ok = idx[np.ix_(ty, tx)], keep[np.ix_(ty, tx)]
    return {k: frame[(pix == k) & ok].mean(0) for k in np.unique(pix) if ((pix == k) & ok).any()}


def fig6(ctx):
    """The ColorChecker under the three booth lamps at one white balance, beside the reference."""
    names, refl = scene_palette(ctx, 'colorchecker')
    rows, panels, refs = [], [], []
    order = ['d65-fluorescent', 'd50-fluorescent', 'tungsten']
    for lamp in order:
        frame = ctx.run.render('fig6', TITLES[lamp],
                               ['--scene', ctx.scene('colorchecker'), '--light', lamp,
                                '--tilt', '10', '--size', ctx.size(275, 185)],
                               ctx.panel(f'fig6-{lamp}.exr'))
        spd = ctx.colour.ill[LAMPS[lamp]]
        white = ctx.colour.xyz(spd, np.ones_like(spd))
        ref = {k: ctx.colour.xyz(spd, refl[k]) for k in range(24)}
        got = patch_means(ctx, 'colorchecker', frame)
        # Exposure: the one scale that best maps the reference Y onto the rendered Y.
        s = sum(got[k][1] * ref[k][1] for k in range(24)) / sum(ref[k][1] ** 2 for k in range(24))
        for k in range(24):
            lr, lg = fl.lab(ref[k], white), fl.lab(got[k], s * white)
            # The light falls unevenly on the chart (the booth's luminance map): the same
            # patch at the reference's lightness separates colour from level.
            ratio = got[k][1] / (s * ref[k][1])
            rows.append([lamp, LAMPS[lamp], names[k], *ref[k], *lr, *got[k], *lg,
                         fl.de00(lr, lg), s, ratio,
                         fl.de00(lr, fl.lab(got[k] / ratio, s * white))])
        panels.append(frame)
        refs.append((ref, s))
    fl.write_csv(ctx.path('fig6.csv'),
                 ['lamp', 'cie_illuminant', 'patch', 'ref_X', 'ref_Y', 'ref_Z', 'ref_L', 'ref_a',
                  'ref_b', 'render_X_cdm2', 'render_Y_cdm2', 'render_Z_cdm2', 'render_L',
                  'render_a', 'render_b', 'de00', 'exposure_cdm2_per_ref_Y', 'level_ratio',
                  'de00_at_ref_level'], rows,
                 'ColorChecker under each booth lamp: reference XYZ from the reflectances x the lamp '
                 'SPD x CIE 1931 (perfect white Y = 100), the rendered patch mean (cd/m^2), CIELAB '
                 'of each against the lamp white (the render\'s at the exposure scale), CIEDE2000, the '
                 'patch\'s level against the chart\'s (level_ratio: the uneven light) and '
                 'CIEDE2000 with the rendered patch brought to the reference\'s level')
    figshape.fig6(ctx, order, panels, refs, rows)
    fl.write_caption(ctx.path('fig6.txt'), 'Fig. 6: the ColorChecker as the light changes',
                     'Left to right: the D65, D50 and tungsten booth lamps. Top: the rendered '
                     'virtual ColorChecker (replica render, absolute XYZ); bottom: the '
                     'reflectances\' reference colours under the same lamp (CIE 1931, the lamp SPD). '
                     f'Both shown at one fixed white balance (CCT {WB_CCT:.0f} K, as the paper: not '
                     'colour balanced, so the light\'s colour shows) and one exposure; panel tilted '
                     '10 degrees back, eye on the default view, so no highlight of the lamp '
                     'veils the chart. The booth light falls unevenly on the chart (its '
                     'luminance map, Fig. 2), so the rendered patches differ from the flat '
                     'reference in level by row; fig6.csv gives per patch the XYZ, CIELAB, '
                     'CIEDE2000 (rendered against reference), the level ratio and CIEDE2000 '
                     'at the reference\'s level (the colour alone).',
                     ctx.run.commands['fig6'])


def fig7(ctx):
    """The metamer target: pairs that match under tungsten and differ under D65."""
    names, refl = scene_palette(ctx, 'metamer')
    pairs = (len(refl) - 1) // 2
    rows, panels = [], {}
    for lamp in ['tungsten', 'd50-fluorescent', 'd65-fluorescent']:
        frame = ctx.run.render('fig7', TITLES[lamp],
                               ['--scene', ctx.scene('metamer'), '--light', lamp,
                                '--size', ctx.size(240, 160)], ctx.panel(f'fig7-{lamp}.exr'))
        spd = ctx.colour.ill[LAMPS[lamp]]
        white = ctx.colour.xyz(spd, np.ones_like(spd))
        got = patch_means(ctx, 'metamer', frame)
        # The rendered white: the surround's (a known reflectance) rendered level.
        s = got[0][1] / ctx.colour.xyz(spd, refl[0])[1]
        for p in range(pairs):
            a, b = 1 + 2 * p, 2 + 2 * p
            ref = fl.de00(fl.lab(ctx.colour.xyz(spd, refl[a]), white),
                          fl.lab(ctx.colour.xyz(spd, refl[b]), white))
            ren = fl.de00(fl.lab(got[a], s * white), fl.lab(got[b], s * white))
            rows.append([lamp, LAMPS[lamp], f'pair{p + 1:02d}', names[a], names[b], ref, ren,
                         *got[a], *got[b]])
        panels[lamp] = frame
    fl.write_csv(ctx.path('fig7.csv'),
                 ['lamp', 'cie_illuminant', 'pair', 'a', 'b', 'de00_reflectances',
                  'de00_rendered', 'a_X_cdm2', 'a_Y_cdm2', 'a_Z_cdm2', 'b_X_cdm2', 'b_Y_cdm2',
                  'b_Z_cdm2'], rows,
                 'Metamer pairs under each booth lamp: CIEDE2000 between the two halves of each '
                 'row from the reflectances (lamp SPD, CIE 1931) and from the rendered frame '
                 '(patch means, white from the surround)')
    figshape.fig7(ctx, panels, rows, pairs)
    fl.write_caption(ctx.path('fig7.txt'), 'Fig. 7: metameric samples',
                     'The shipped metamer target (data/scenes/metamer: six pairs from '
                     'data/scenes/metamers/metamers_A_D65.csv) rendered under the tungsten lamp '
                     '(left) and the D65 simulator (right), one fixed white balance (CCT '
                     f'{WB_CCT:.0f} K). Each row holds two samples whose spectra match under '
                     'tungsten and differ under D65; the CIEDE2000 of each row (from the rendered '
                     'frame) is printed beside it. fig7.csv: each pair under every booth lamp, '
                     'from the reflectances and from the frame.', ctx.run.commands['fig7'])


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument('out_dir')
    ap.add_argument('--replica', required=True)
    ap.add_argument('--data', required=True)
    ap.add_argument('--scale', type=float, default=2.0)
    ap.add_argument('--only', default='2,3,4,5,6,7')
    ap.add_argument('--gl', action='store_true')
    args = ap.parse_args()
    ctx = Context(args)
    figures = {'2': figures_more.fig2, '3': figures_more.fig3, '4': figures_more.fig4,
               '5': figures_more.fig5, '6': fig6, '7': fig7}
    for n in args.only.split(','):
        if n not in figures:
            ap.error(f'--only: no figure {n} (2-7)')
    for n in sorted(args.only.split(',')):
        fl.progress(f'fig{n}: start')
        figures[n](ctx)
        fl.progress(f'fig{n}: wrote {ctx.path(f"fig{n}.png")}')
    return 0


if __name__ == '__main__':
    sys.exit(main())
