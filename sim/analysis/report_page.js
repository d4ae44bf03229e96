// Draws the charts of a tpsim report page from the JSON blob #tpsim-data, then records in
// #chart-status whether every chart drew its data (the headless-browser test reads it).
(function () {
    'use strict';
    const palette = ['#4e79a7', '#f28e2b', '#59a14f', '#e15759', '#76b7b2', '#b07aa1', '#edc948'];
    const data = JSON.parse(document.getElementById('tpsim-data').textContent);
    const failures = [];
    let drawn = 0;

    function rgb(hex) {
        return [1, 3, 5].map(function (i) { return parseInt(hex.substr(i, 2), 16); });
    }
    // True when the canvas shows enough pixels of the colour: data was drawn, not only axes.
    function showsColour(canvas, hex) {
        const want = rgb(hex);
        const pixels = canvas.getContext('2d').getImageData(0, 0, canvas.width, canvas.height).data;
        let matching = 0;
        for (let i = 0; i < pixels.length; i += 4) {
            if (pixels[i + 3] > 200 && Math.abs(pixels[i] - want[0]) < 24 &&
                Math.abs(pixels[i + 1] - want[1]) < 24 && Math.abs(pixels[i + 2] - want[2]) < 24)
                matching++;
        }
        return matching >= 20;
    }
    function nonzero(dataset) {
        return dataset.data.some(function (v) {
            const y = v !== null && typeof v === 'object' ? v.y : v;
            return y !== null && y !== 0;
        });
    }
    // Scatter charts (error against cycles) label their points: {x, y, label}.
    function pointLabel(context) {
        const raw = context.raw;
        return (raw && raw.label ? raw.label + ': ' : '') + context.formattedValue;
    }
    // Points with an interval, {x, y, yMin, yMax}, get a vertical bar from yMin to yMax in
    // their dataset's colour (sample-check: an estimate's error and its confidence interval).
    const errorBars = {
        id: 'errorBars',
        afterDatasetsDraw: function (chart) {
            const ctx = chart.ctx, y = chart.scales.y, area = chart.chartArea;
            chart.data.datasets.forEach(function (dataset, k) {
                const meta = chart.getDatasetMeta(k);
                if (meta.hidden) return;
                ctx.save();
                ctx.beginPath();  // a bar longer than the value range is cut at its edge
                ctx.rect(area.left, area.top, area.right - area.left, area.bottom - area.top);
                ctx.clip();
                ctx.strokeStyle = dataset.borderColor;
                ctx.lineWidth = 1.5;
                dataset.data.forEach(function (p, i) {
                    if (p === null || typeof p !== 'object' || p.yMin === undefined) return;
                    const x = meta.data[i].x, top = y.getPixelForValue(p.yMax),
                          bottom = y.getPixelForValue(p.yMin);
                    ctx.beginPath();
                    ctx.moveTo(x, top);
                    ctx.lineTo(x, bottom);
                    ctx.moveTo(x - 4, top);
                    ctx.lineTo(x + 4, top);
                    ctx.moveTo(x - 4, bottom);
                    ctx.lineTo(x + 4, bottom);
                    ctx.stroke();
                });
                ctx.restore();
            });
        }
    };
    // Points with a tag, {x, y, tag}, get it written beside them (the Pareto charts number
    // their jobs; a table under the charts says which is which).
    const pointTags = {
        id: 'pointTags',
        afterDatasetsDraw: function (chart) {
            const ctx = chart.ctx;
            ctx.save();
            ctx.font = '11px system-ui, sans-serif';
            ctx.fillStyle = '#1f2430';
            // Points drawn on (or next to) each other share one label: "3, 4".
            const placed = [];
            chart.data.datasets.forEach(function (dataset, k) {
                const meta = chart.getDatasetMeta(k);
                if (meta.hidden) return;
                dataset.data.forEach(function (p, i) {
                    if (p === null || typeof p !== 'object' || p.tag === undefined) return;
                    const x = meta.data[i].x, y = meta.data[i].y;
                    const near = placed.find(function (q) {
                        return Math.abs(q.x - x) < 8 && Math.abs(q.y - y) < 8;
                    });
                    if (near) near.text += ', ' + p.tag;
                    else placed.push({ x: x, y: y, text: String(p.tag) });
                });
            });
            placed.forEach(function (q) { ctx.fillText(q.text, q.x + 6, q.y - 6); });
            ctx.restore();
        }
    };
    // The value range the error bars need (Chart.js scales to the points' y alone), or the one
    // the page chose (spec.range: [min, max]).
    function barRange(spec) {
        if (spec.range) return { suggestedMin: spec.range[0], suggestedMax: spec.range[1] };
        let lo = Infinity, hi = -Infinity;
        spec.datasets.forEach(function (d) {
            d.data.forEach(function (p) {
                if (p === null || typeof p !== 'object' || p.yMin === undefined) return;
                lo = Math.min(lo, p.yMin);
                hi = Math.max(hi, p.yMax);
            });
        });
        return lo <= hi ? { suggestedMin: lo, suggestedMax: hi } : {};
    }
    function options(spec) {
        const scatter = spec.type === 'scatter';
        const valueAxis = Object.assign({
            type: spec.log ? 'logarithmic' : 'linear',
            beginAtZero: spec.zero && !spec.log && !scatter,
            grace: spec.zero ? 0 : '8%',
            title: { display: !!spec.unit, text: spec.unit },
            ticks: spec.percent ? { callback: function (v) { return v + ' %'; } } : {},
            // Errors are read against 0, the true value: its grid line stands out.
            grid: { color: function (c) { return c.tick && c.tick.value === 0 && scatter
                                                 ? '#5b6170' : 'rgba(0, 0, 0, 0.1)'; } }
        }, barRange(spec));
        // Timelines ({x, y} points) span exactly cycle 0 to the last sample; a line over
        // labels (a sweep's axis values) has them as categories.
        const timeline = spec.type === 'line' && spec.labels.length === 0;
        const lastCycle = timeline
            ? Math.max.apply(null, spec.datasets[0].data.map(function (p) { return p.x; })) : 0;
        const categoryAxis = timeline
            ? { type: 'linear', min: 0, max: lastCycle, title: { display: true, text: 'cycle' } }
            : spec.type === 'line'
            ? { title: { display: true, text: spec.xTitle } }
            : scatter
            ? { type: spec.xLog ? 'logarithmic' : 'linear', grace: '3%',
                title: { display: true, text: spec.xTitle } }
            : { ticks: { autoSkip: false } };
        return {
            animation: false,
            responsive: true,
            maintainAspectRatio: false,
            indexAxis: spec.horizontal ? 'y' : 'x',
            plugins: {
                title: { display: true, text: spec.title, font: { size: 14 } },
                legend: { display: spec.datasets.length > 1 },
                tooltip: scatter ? { callbacks: { label: pointLabel } } : {}
            },
            scales: spec.horizontal ? { x: valueAxis, y: categoryAxis }
                                    : { x: categoryAxis, y: valueAxis }
        };
    }

    data.charts.forEach(function (spec, index) {
        const canvas = document.querySelector('canvas[data-chart="' + index + '"]');
        try {
            const datasets = spec.datasets.map(function (d, k) {
                const colour = palette[k % palette.length];
                return { label: d.label, data: d.data, backgroundColor: colour,
                         borderColor: colour, borderWidth: spec.type === 'bar' ? 0 : 2,
                         pointRadius: spec.type === 'scatter' ||
                                      (spec.type === 'line' && spec.labels.length) ? 4 : 0,
                         showLine: spec.type !== 'scatter' || !!d.line };
            });
            new Chart(canvas, { type: spec.type, data: { labels: spec.labels, datasets: datasets },
                                options: options(spec), plugins: [errorBars, pointTags] });
            const shown = datasets.findIndex(function (d) { return nonzero(d); });
            if (shown < 0 || !showsColour(canvas, datasets[shown].backgroundColor))
                throw new Error('no data drawn');
            canvas.dataset.drawn = 'yes';
            drawn++;
        } catch (e) {
            if (canvas) canvas.dataset.drawn = 'no';
            failures.push(spec.title + ': ' + e.message);
        }
    });

    const errors = window.tpsimErrors.concat(failures);
    const status = document.getElementById('chart-status');
    status.dataset.status = errors.length === 0 && drawn === data.charts.length ? 'ok' : 'failed';
    status.textContent = 'charts drawn: ' + drawn + ' of ' + data.charts.length + '; errors: ' +
                         errors.length + (errors.length ? ' (' + errors.join('; ') + ')' : '');
})();
