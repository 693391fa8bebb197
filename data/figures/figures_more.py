"""The paper's Figs. 2-5 for 'replica figures' (figures.py): the booth lamps' luminance images,
the painting's shading, its shadowing as the panel tilts, and a curved glossy surface."""
import json
import os

import matplotlib.pyplot as plt
import numpy as np

import figlib as fl

WB_CCT = 5500.0
TILTS = (40, 20, 0, -10)
SHADOW = 0.8  # a pixel below this fraction of its image's median is counted as shadowed
LAMP_TITLES = {'tungsten': '(A) tungsten', 'd50-fluorescent': '(B) D50 simulator',
               'd65-fluorescent': '(C) D65 simulator'}


def fig2(ctx):
    """The three booth lamps' luminance images (the booth model's EXRs) on one scale."""
    booth = os.path.join(ctx.data, 'booth')
    lights = json.load(open(os.path.join(booth, 'booth.json')))['lights']
    images, rows = [], []
    for light in lights:
        path = os.path.relpath(os.path.join(booth, light['luminance']))
        fl.progress(f'fig2: reading {path}')
        y = fl.read_exr(path)['Y']
        images.append((light['name'], y))
        rows.append([light['name'], light['luminance'], y.shape[1], y.shape[0],
                     float(y.min()), float(y.max()), float(y.mean())])
    lo = min(r[4] for r in rows)
    hi = max(r[5] for r in rows)
    fig, ax = plt.subplots(1, 3, figsize=(11, 2.9))
    for a, (name, y) in zip(ax, images):
        im = a.imshow(y, cmap='inferno', vmin=lo, vmax=hi)
        a.set_title(LAMP_TITLES.get(name, name), fontsize=10)
        a.set_xticks([])
        a.set_yticks([])
    bar = fig.colorbar(im, ax=list(ax), fraction=0.025, pad=0.02)
    bar.set_label('luminance (cd/m²)')
    fig.suptitle('Fig. 2: the booth lamps\' luminance, as the renderer maps them on the ceiling',
                 fontsize=11)
    ctx.save(fig, 2)
    fl.write_csv(ctx.path('fig2.csv'), ['lamp', 'file', 'width', 'height', 'min_cdm2',
                                        'max_cdm2', 'mean_cdm2'],
                 rows + [['scale bar', '', '', '', lo, hi, '']],
                 'The booth lamps\' luminance images (data/booth/*.exr): each image\'s range and '
                 'mean; the last row is the scale bar\'s range (all three images share it)')
    fl.write_caption(ctx.path('fig2.txt'), 'Fig. 2: the booth lamps\' spatial luminance',
                     'The luminance images of the three lamps as the booth model holds them '
                     '(data/booth/booth.json: tungsten, a D50 and a D65 fluorescent simulator), '
                     'mapped on the booth ceiling by the renderer; one colour scale for the '
                     f'three, {lo:.0f} to {hi:.0f} cd/m². No command renders them: they are the '
                     'model\'s own images (made by replica booth generate, or by replica booth '
                     'build from a site\'s HDR captures).',
                     [(r[0], f'{os.path.relpath(os.path.join(booth, r[1]))}, channel Y (no render)')
                      for r in rows])


def mats(img, texels_per_mm, white):
    """The paper's surround: a white mat, a black mat and a black frame around the render (sRGB).
    They are drawn here; on the appliance they are real objects around the screen."""
    out = img
    for width_mm, colour in ((12, white), (8, 0.03), (10, 0.0)):
        n = max(2, round(width_mm * texels_per_mm))
        out = np.pad(out, ((n, n), (n, n), (0, 0)), constant_values=colour)
    return out


def fig3(ctx):
    """The painting shading-only, surrounded by a white mat, a black mat and a black frame."""
    size = ctx.size(384, 288)
    frame = ctx.run.render('fig3', 'painting, shading only, tungsten, tilt 10',
                           ['--scene', ctx.scene('painting'), '--light', 'tungsten',
                            '--tilt', '10', '--shading-only', '--size', size],
                           ctx.panel('fig3-painting-shading.exr'))
    y = frame[..., 1]
    exposure = 1.4 * float(np.median(y))
    img = fl.srgb(frame, 2856.0, exposure)
    # A white mat (reflectance 0.9) where the painting's neutral white (0.8) is at its median.
    lin = min(1.0, float(np.median(y)) * 0.9 / 0.8 / exposure)
    white = 1.055 * lin ** (1 / 2.4) - 0.055
    fig, ax = plt.subplots(figsize=(6, 4.8))
    ax.imshow(mats(img, frame.shape[1] / 240.0, white))
    ax.set_xticks([])
    ax.set_yticks([])
    ax.set_title('Fig. 3: the painting without its colour: shading and shadowing only',
                 fontsize=10)
    fig.tight_layout()
    ctx.save(fig, 3)
    fl.write_csv(ctx.path('fig3.csv'), ['quantity', 'value'],
                 [['median_Y_cdm2', float(np.median(y))],
                  ['p5_Y_cdm2', float(np.percentile(y, 5))],
                  ['p95_Y_cdm2', float(np.percentile(y, 95))],
                  ['shadowed_fraction', float((y < SHADOW * np.median(y)).mean())]],
                 'The shading-only painting: luminance percentiles and the fraction of pixels '
                 f'below {SHADOW} of the median (shadowed)')
    fl.write_caption(ctx.path('fig3.txt'), 'Fig. 3: the painting\'s shading and shadowing',
                     'The shipped painting rendered with its colour replaced by a neutral white '
                     '(replica render --shading-only: reflectance 0.8 at every wavelength), so '
                     'that only the shading and shadowing of its canvas weave and impasto show '
                     '(tungsten lamp, panel tilted 10 degrees back, white balanced for the lamp). '
                     'The white mat, black mat and black frame are drawn around the render: the '
                     'scene holds only the painting (on the appliance, as in the paper, they '
                     'are real objects around the screen).', ctx.run.commands['fig3'])




def fig4(ctx):
    """Crops of the shading-only painting as the panel tilts down and away from the lamp."""
    size = ctx.size(384, 288)
    rows, crops = [], []
    for tilt in TILTS:
        frame = ctx.run.render('fig4', f'tilt {tilt} degrees',
                               ['--scene', ctx.scene('painting'), '--light', 'tungsten',
                                '--tilt', str(tilt), '--shading-only', '--size', size],
                               ctx.panel(f'fig4-tilt{tilt}.exr'))
        h, w = frame.shape[:2]
        box = (int(0.05 * w), int(0.45 * h), int(0.05 * w) + w // 3, int(0.45 * h) + h // 3)
        crop = frame[box[1]:box[3], box[0]:box[2]]
        y = crop[..., 1]
        med = float(np.median(y))
        rows.append([tilt, *box, float(y.mean()), med, float(np.percentile(y, 5)),
                     float((y < SHADOW * med).mean())])
        crops.append(crop)
    fig, ax = plt.subplots(1, len(TILTS), figsize=(3 * len(TILTS), 3.2))
    for a, crop, r in zip(ax, crops, rows):
        a.imshow(fl.srgb(crop, 2856.0, 1.6 * r[6]), interpolation='nearest')
        a.set_title(f'tilt {r[0]}°: shadowed {100 * r[8]:.1f} %', fontsize=9)
        a.set_xticks([])
        a.set_yticks([])
    fig.suptitle('Fig. 4: more shadowing as the panel tilts down and away from the overhead lamp',
                 fontsize=11)
    fig.tight_layout()
    ctx.save(fig, 4)
    fl.write_csv(ctx.path('fig4.csv'), ['tilt_deg', 'crop_x0', 'crop_y0', 'crop_x1', 'crop_y1',
                                        'mean_Y_cdm2', 'median_Y_cdm2', 'p5_Y_cdm2',
                                        'shadowed_fraction'], rows,
                 'Each crop (pixels of the frame) at each tilt: luminance and the fraction of '
                 f'pixels below {SHADOW} of the crop\'s median (shadowed)')
    fl.write_caption(ctx.path('fig4.txt'), 'Fig. 4: shadowing as the panel tilts',
                     'The same ninth of the shading-only painting (Fig. 3, lower left) as the '
                     f'panel turns from {TILTS[0]} degrees back to {-TILTS[-1]} degrees forward '
                     f'({", ".join(map(str, TILTS))} degrees; positive leans back), down and '
                     'away from the overhead tungsten lamp: the light grazes the relief more and '
                     'the shadows grow. Each crop is the view perpendicular to the screen (a '
                     'screen capture, as in the paper), shown at its own exposure (its median '
                     'at the same grey) so that the shadows, not the falling level, compare. '
                     f'fig4.csv: crop boxes, luminance and the shadowed fraction (pixels below '
                     f'{SHADOW} of the crop\'s median).',
                     ctx.run.commands['fig4'])


def fig5(ctx):
    """A curved glossy surface mirroring the tungsten and the D65 lamp."""
    size = ctx.size(240, 160)
    frames, rows = {}, []
    for lamp, cct in (('tungsten', 2856.0), ('d65-fluorescent', 6500.0)):
        f = ctx.run.render('fig5', lamp, ['--scene', ctx.scene('glossy-cylinder'), '--light',
                                          lamp, '--tilt', '30', '--size', size],
                           ctx.panel(f'fig5-{lamp}.exr'))
        frames[lamp] = f
        y = f[..., 1]
        row = np.argmax(y.max(1))
        rows.append([lamp, float(y.max()), float(np.median(y)), int(row),
                     float((y > 0.5 * y.max()).mean())])
    fig, ax = plt.subplots(1, 2, figsize=(10, 3.8))
    for a, (lamp, f) in zip(ax, frames.items()):
        a.imshow(fl.srgb(f, WB_CCT, 1.0 * f[..., 1].max()))
        a.set_title(lamp, fontsize=10)
        a.set_xticks([])
        a.set_yticks([])
    fig.suptitle('Fig. 5: the booth lamp mirrored on a curved glossy surface: tungsten (left), '
                 'D65 (right)', fontsize=11)
    fig.tight_layout()
    ctx.save(fig, 5)
    fl.write_csv(ctx.path('fig5.csv'), ['lamp', 'peak_Y_cdm2', 'median_Y_cdm2', 'peak_row',
                                        'highlight_fraction'], rows,
                 'The glossy cylinder under each lamp: the highlight\'s peak luminance and row, '
                 'the median, and the fraction of pixels over half the peak')
    fl.write_caption(ctx.path('fig5.txt'), 'Fig. 5: reflections of the lamps on a curved surface',
                     'The shipped glossy cylinder (data/scenes/glossy-cylinder: a 0.15 m radius '
                     'segment, deep blue under a clear gloss coat, Ward alpha 0.05) under the '
                     'tungsten lamp (left) and the D65 simulator (right), white balance fixed at '
                     f'{WB_CCT:.0f} K; each lamp\'s own luminance map (Fig. 2) shapes its '
                     'highlight.', ctx.run.commands['fig5'])
