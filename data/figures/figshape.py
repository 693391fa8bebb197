"""Layouts of the paper's Figs. 6 and 7 (figures.py renders and measures; this draws)."""
import matplotlib.pyplot as plt
import numpy as np

import figlib as fl

WB_CCT = 5500.0


def fig6(ctx, order, panels, refs, rows):
    """Top row the rendered charts, bottom row the reference colours, one column a lamp; one white
    balance (5500 K) and one exposure for all six."""
    white_y = max(p[..., 1].max() for p in panels)
    exposure = 1.05 * white_y
    fig, ax = plt.subplots(2, 3, figsize=(10.5, 5.8))
    for c, lamp in enumerate(order):
        ax[0, c].imshow(fl.srgb(panels[c], WB_CCT, exposure))
        de = [r[15] for r in rows if r[0] == lamp]
        dc = [r[18] for r in rows if r[0] == lamp]
        ax[0, c].set_title(f'{lamp}: rendered\nCIEDE2000 mean {np.mean(de):.1f} '
                           f'(at the reference level {np.mean(dc):.2f})', fontsize=9)
        ref, s = refs[c]
        chart = np.zeros((4, 6, 3))
        for k in range(24):
            chart[k // 6, k % 6] = ref[k] * s
        ax[1, c].imshow(fl.srgb(chart, WB_CCT, exposure), interpolation='nearest')
        ax[1, c].set_title(f'{lamp}: reference (reflectances)', fontsize=9)
    for a in ax.flat:
        a.set_xticks([])
        a.set_yticks([])
    fig.suptitle(f'Fig. 6: ColorChecker under D65, D50 and tungsten, white balance fixed at '
                 f'{WB_CCT:.0f} K', fontsize=11)
    fig.tight_layout()
    ctx.save(fig, 6)


def fig7(ctx, panels, rows, pairs):
    """The target under tungsten (left) and the D65 simulator (right), each row's CIEDE2000."""
    lamps = ['tungsten', 'd65-fluorescent']
    exposure = 1.3 * max(panels[lamp][..., 1].max() for lamp in lamps)
    fig, ax = plt.subplots(1, 2, figsize=(10, 3.8))
    for c, lamp in enumerate(lamps):
        img = panels[lamp]
        ax[c].imshow(fl.srgb(img, WB_CCT, exposure), extent=(0, 240, 160, 0))
        pitch = 150 // pairs
        top = (160 - pairs * pitch + (pitch - pitch * 4 // 5)) // 2
        for p, r in enumerate([r for r in rows if r[0] == lamp]):
            y = top + p * pitch + pitch * 4 // 5 / 2
            ax[c].text(236, y, f'{r[6]:.2f}', ha='right', va='center', fontsize=8,
                       color='black', bbox=dict(facecolor='white', alpha=0.7, lw=0, pad=1))
        ax[c].set_title(f'{lamp}: CIEDE2000 of each row (rendered)', fontsize=9)
        ax[c].set_xticks([])
        ax[c].set_yticks([])
    fig.suptitle('Fig. 7: metameric pairs match under tungsten and differ under D65 '
                 f'(white balance {WB_CCT:.0f} K)', fontsize=11)
    fig.tight_layout()
    ctx.save(fig, 7)
