// A static file server for web/ (no server logic: any static server does). `npm run serve`
// serves the page on http://localhost:8080 (PORT to change it); the tests start one on a free
// port.
import http from 'node:http';
import { fileURLToPath } from 'node:url';
import path from 'node:path';
import handler from 'serve-handler';

const root = path.dirname(fileURLToPath(import.meta.url));

export function serve(port = 0) {
  const server = http.createServer((request, response) => handler(request, response, {
    public: root,
    directoryListing: false,
  }));
  return new Promise((resolve) => {
    server.listen(port, '127.0.0.1', () => resolve(server));
  });
}

if (process.argv[1] === fileURLToPath(import.meta.url)) {
  const server = await serve(Number(process.env.PORT ?? 8080));
  console.log(`Glint's page: http://localhost:${server.address().port}/`);
}
